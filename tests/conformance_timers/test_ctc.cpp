// CTC mode (firmware/conformance/timers/tmr_ctc): every timer toggles OCnA on
// compare match.
//
// ATmega328P datasheet (DS40002061A) §15.7.2, §16.9.2, §18.7.2 (and the same
// sections of the ATmega2560 §16.7.2, §17.9.2, §20.7.2 and the ATmega32's
// Timer/Counter chapters): TCNTn is cleared on the timer clock after it
// matched OCRnA, so a compare match, and an OCnA toggle, comes every
// (OCRnA + 1) * N cycles; "f_OCnA = f_clk_I/O / (2 * N * (1 + OCRnA))".
// TOVn is set only "in the same timer clock cycle that the counter counts
// from MAX to 0x00": never, while TCNTn stays <= OCRnA.
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

struct Channel {
    const char* pin;
    Cycle interval;  // (OCRnA + 1) * N, see tmr_ctc/main.c
};

void expect_ctc(const TimerPart& part, const std::vector<Channel>& channels, std::uint8_t all_timers) {
    Mcu mcu(timer_firmware("tmr_ctc", part));
    ASSERT_EQ(mcu.mcu_type(), part.mcu);
    std::vector<std::unique_ptr<PinLog>> logs;
    for (const auto& c : channels) logs.push_back(std::make_unique<PinLog>(mcu, c.pin));
    mcu.run_for(60000);
    for (std::size_t i = 0; i < channels.size(); ++i) {
        const std::size_t expected_edges = 60000 / channels[i].interval - 2;
        EXPECT_TRUE(all_equal(logs[i]->intervals(), channels[i].interval, expected_edges - 1)) << channels[i].pin;
    }
    EXPECT_EQ(mcu.read_ram_u8("ocf_seen"), all_timers);
    EXPECT_EQ(mcu.read_ram_u8("tov_seen"), 0) << "TOVn set although TCNTn never passed MAX";
}

// Timer0: (99 + 1) * 8 = 800; Timer1: (1233 + 1) * 1 = 1234;
// Timer2: (49 + 1) * 32 = 1600 (Timer2 prescaler, Table 18-9: CS22:0 = 011 is clk/32).
TEST(TimerCtc, ToggleIntervalIsOcrPlusOneTimesPrescalerAtmega328p) {
    expect_ctc(kAtmega328p, {{"PD6", 800}, {"PB1", 1234}, {"PB3", 1600}}, 0x07);
}

// Same, plus Timer3: 3000 * 1, Timer4: (99 + 1) * 64 = 6400, Timer5: 4096 * 1.
TEST(TimerCtc, ToggleIntervalIsOcrPlusOneTimesPrescalerAtmega2560) {
    expect_ctc(kAtmega2560,
               {{"PB7", 800}, {"PB5", 1234}, {"PB4", 1600}, {"PE3", 3000}, {"PH3", 6400}, {"PL3", 4096}}, 0x3F);
}

// ATmega32: OC0 = PB3, OC1A = PD5, OC2 = PD7. Timer/Counter2 CS22:0 = 011 is
// clk/32 ("Timer/Counter2 Prescaler", TCCR2 Table 54): (49 + 1) * 32 = 1600.
TEST(TimerCtc, ToggleIntervalIsOcrPlusOneTimesPrescalerAtmega32) {
    expect_ctc(kAtmega32, {{"PB3", 800}, {"PD5", 1234}, {"PD7", 1600}}, 0x07);
}

}  // namespace
}  // namespace avrbench::test::timers
