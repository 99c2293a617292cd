// CTC with OCRnA = 0 at prescaler 1 (firmware/conformance/timers/tmr_ctc_ocr0).
//
// ATmega328P datasheet §15.7.2 / §16.9.2 / §18.7.2: in CTC mode the counter is
// cleared on the timer clock after TCNTn == OCRnA; with OCRnA = 0 that is
// every timer clock, "a maximum frequency of f_OC0 = f_clk_I/O/2 when OCR0A is
// set to zero": OCnA toggles on every cycle at prescaler 1, and OCFnA is set on
// every cycle. simavr 1.6 schedules a timer only when its period is more than
// one cycle: nothing happens at all.
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

void expect_every_cycle(const TimerPart& part, const std::vector<const char*>& pins, const char* oc1a) {
    Mcu mcu(timer_firmware("tmr_ctc_ocr0", part));
    std::vector<std::unique_ptr<PinLog>> logs;
    for (const char* p : pins) logs.push_back(std::make_unique<PinLog>(mcu, p));
    while (mcu.read_ram_u8("phase") != 1 && mcu.cycle() < 2000) mcu.run_for(1);
    ASSERT_EQ(mcu.read_ram_u8("phase"), 1);
    for (std::size_t i = 0; i < pins.size(); ++i) {
        // Each timer runs for the 200-cycle delay plus the start/stop writes
        // around it: at least 200 toggles, each one cycle after the previous.
        EXPECT_TRUE(all_equal(logs[i]->intervals(), 1, 199)) << pins[i];
    }

    // Phase 2: the OCIE1A interrupt enabled while OCR1A = 0; its first run sets
    // OCR1A = 1999: from then on a match every 2000 cycles.
    PinLog oc1(mcu, oc1a);
    mcu.run_for(30000);
    EXPECT_EQ(mcu.read_ram_u16("ocr_at_first_isr"), 0);
    // The first run comes within a few cycles of the start, then one every
    // 2000 cycles: 1 + 30000 / 2000 = 16 in 30000 cycles, give or take the first.
    EXPECT_GE(mcu.read_ram_u8("isr_count"), 15);
    EXPECT_LE(mcu.read_ram_u8("isr_count"), 16);
    const auto intervals = oc1.intervals();
    ASSERT_GE(intervals.size(), 12u);
    const std::vector<Cycle> last(intervals.end() - 12, intervals.end());
    EXPECT_TRUE(all_equal(last, 2000, 12));
    EXPECT_TRUE(mcu.findings().empty());
}

TEST(TimerCtcOcrZero, MatchesEveryCycleAndTheIsrRunsAtOnceAtmega328p) {
    expect_every_cycle(kAtmega328p, {"PD6", "PB1", "PB3"}, "PB1");
}

TEST(TimerCtcOcrZero, MatchesEveryCycleAndTheIsrRunsAtOnceAtmega2560) {
    expect_every_cycle(kAtmega2560, {"PB7", "PB5", "PB4", "PE3", "PH3", "PL3"}, "PB5");
}

TEST(TimerCtcOcrZero, MatchesEveryCycleAndTheIsrRunsAtOnceAtmega32) {
    expect_every_cycle(kAtmega32, {"PB3", "PD5", "PD7"}, "PD5");
}

}  // namespace
}  // namespace avrbench::test::timers
