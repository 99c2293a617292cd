// A timer switched into CTC or fast PWM (TOP = OCRnA) from any mode at any
// point of that mode's period counts up (firmware/conformance/timers/
// tmr_mode_switch). ATmega2560 §17.9.1-2 / ATmega328P §16.9.1-2: in Normal,
// CTC and fast PWM modes "the counting direction is always up"; only the
// dual-slope modes count down. Counting up with TOP = 99 at clk/1, the OCnA
// toggles after the first come exactly TOP + 1 = 100 cycles apart.
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

struct Block {
    const char* timer;
    const char* oc_pin;  // OCnA
    unsigned cases;      // from-modes x 8 phases
    const char* to;      // the to-mode, for messages
};

void expect_counts_up(const TimerPart& part, const char* marker0, const char* marker1, const std::vector<Block>& blocks) {
    Mcu mcu(timer_firmware("tmr_mode_switch", part));
    PinLog switches(mcu, marker0), ends(mcu, marker1);
    std::map<std::string, std::unique_ptr<PinLog>> oc;
    for (const auto& b : blocks) {
        if (oc.count(b.oc_pin) == 0) oc[b.oc_pin] = std::make_unique<PinLog>(mcu, b.oc_pin);
    }
    for (int slice = 0; slice < 400 && mcu.read_ram_u8("done") == 0; ++slice) mcu.run_for(1'000'000);
    ASSERT_EQ(mcu.read_ram_u8("done"), 1) << part.mcu << ": the firmware did not finish";
    EXPECT_EQ(mcu.read_ram_u16("gave_up"), 0) << part.mcu << ": switches that never saw 6 compare matches";
    const auto starts = switches.cycles(), stops = ends.cycles();
    unsigned total = 0;
    for (const auto& b : blocks) total += b.cases;
    ASSERT_EQ(starts.size(), total);
    ASSERT_EQ(stops.size(), total);
    ASSERT_EQ(mcu.read_ram_u16("cases"), total);
    std::size_t index = 0;
    for (const auto& b : blocks) {
        const auto edges = oc[b.oc_pin]->cycles();
        for (unsigned c = 0; c < b.cases; ++c, ++index) {
            std::vector<Cycle> inside;
            for (Cycle e : edges) {
                if (e > starts[index] && e <= stops[index]) inside.push_back(e);
            }
            const auto intervals = PinLog::differences(inside);
            // Six matches: five intervals after the first, all TOP + 1 = 100.
            const bool ok = intervals.size() >= 5 &&
                            std::all_of(intervals.end() - 5, intervals.end(), [](Cycle i) { return i == 100; });
            EXPECT_TRUE(ok) << part.mcu << " " << b.timer << " into " << b.to << ": from-mode " << c / 8 << " (index), phase "
                            << c % 8 << "/8: " << inside.size() << " OCnA edges";
        }
    }
}

// Timer1 (and 3..5): 15 from-modes (13 is reserved) x 8 phases per to-mode.
constexpr unsigned k16 = 15 * 8;
constexpr unsigned k8 = 6 * 8;      // 8-bit, TCCRnA/B: modes 4 and 6 reserved
constexpr unsigned k8m32 = 4 * 8;   // ATmega32 8-bit timers: 4 modes

TEST(TimerModeSwitch, CountsUpAfterSwitchingFromAnyModeAtAnyPhaseAtmega328p) {
    std::vector<Block> blocks;
    for (const char* to : {"CTC OCR1A", "CTC ICR1", "fast PWM OCR1A"}) blocks.push_back({"Timer1", "PB1", k16, to});
    for (const char* to : {"CTC", "fast PWM OCRA"}) {
        blocks.push_back({"Timer0", "PD6", k8, to});
        blocks.push_back({"Timer2", "PB3", k8, to});
    }
    expect_counts_up(kAtmega328p, "PC0", "PC1", blocks);
}

TEST(TimerModeSwitch, CountsUpAfterSwitchingFromAnyModeAtAnyPhaseAtmega2560) {
    std::vector<Block> blocks;
    for (const char* to : {"CTC OCRnA", "CTC ICRn", "fast PWM OCRnA"}) {
        blocks.push_back({"Timer1", "PB5", k16, to});
        blocks.push_back({"Timer3", "PE3", k16, to});
        blocks.push_back({"Timer4", "PH3", k16, to});
        blocks.push_back({"Timer5", "PL3", k16, to});
    }
    for (const char* to : {"CTC", "fast PWM OCRA"}) {
        blocks.push_back({"Timer0", "PB7", k8, to});
        blocks.push_back({"Timer2", "PB4", k8, to});
    }
    expect_counts_up(kAtmega2560, "PF0", "PF1", blocks);
}

TEST(TimerModeSwitch, CountsUpAfterSwitchingFromAnyModeAtAnyPhaseAtmega32) {
    std::vector<Block> blocks;
    for (const char* to : {"CTC OCR1A", "CTC ICR1", "fast PWM OCR1A"}) blocks.push_back({"Timer1", "PD5", k16, to});
    blocks.push_back({"Timer0", "PB3", k8m32, "CTC"});
    blocks.push_back({"Timer2", "PD7", k8m32, "CTC"});
    expect_counts_up(kAtmega32, "PC0", "PC1", blocks);
}

}  // namespace
}  // namespace avrbench::test::timers
