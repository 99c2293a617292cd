// Timer1 input capture (firmware/conformance/timers/tmr_icp).
//
// ATmega328P datasheet §16.6 "Input Capture Unit" (ATmega2560 §17.6, ATmega32
// "Input Capture Unit"): on the ICP1 edge ICES1 selects, "the 16-bit value of
// the counter (TCNT1) is written to the Input Capture Register (ICR1)" and
// ICF1 is set. §16.6.2 "Noise Canceler": with ICNC1 = 1 "the input is
// monitored over four samples, and all four must be equal for changing the
// output", so a capture comes four system clock cycles later and a pulse
// shorter than that is no edge at all.
// Timer1 counts at clk/1, so ICR1 differences are cycle differences.
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

void expect_captures(const TimerPart& part, const char* icp) {
    Mcu mcu(timer_firmware("tmr_icp", part));
    Pin& pin = mcu.pin(icp);
    pin.drive(false);
    std::vector<Cycle> at;  // the cycle each drive really happened
    auto drive = [&](Cycle when, bool level) {
        mcu.scheduler().at(when, [&, level](Cycle) {
            at.push_back(mcu.cycle());
            pin.drive(level);
        });
    };
    // Four edges without the noise canceler (rise, fall, rise, fall: the
    // vector flips ICES1 after each), which the fourth capture turns on;
    // then rise, fall, a 2-cycle glitch, rise with it.
    drive(2000, true);
    drive(3000, false);
    drive(5000, true);
    drive(5500, false);
    drive(8000, true);
    drive(10000, false);
    drive(12000, true);
    drive(12002, false);
    drive(14000, true);
    mcu.run_for(16000);
    ASSERT_EQ(at.size(), 9u);
    EXPECT_LT(at[7] - at[6], 4u) << "the glitch must be shorter than the four samples";
    EXPECT_EQ(mcu.read_ram_u8("count"), 7) << "six edges and the last rise; the glitch filtered out";
    const auto cap = ram_words(mcu, "cap", 7);
    // Without ICNC1 ICR1 = TCNT1 at the edge; with it, 4 cycles later.
    const std::vector<Cycle> edge = {at[0], at[1], at[2], at[3], at[4] + 4, at[5] + 4, at[8] + 4};
    for (std::size_t i = 1; i < 7; ++i) {
        EXPECT_EQ(static_cast<Cycle>((cap[i] - cap[0]) & 0xFFFF), edge[i] - edge[0]) << "capture " << i;
    }
    EXPECT_TRUE(mcu.findings().empty());
}

TEST(TimerInputCapture, BothEdgesAndTheNoiseCancelerAtmega328p) { expect_captures(kAtmega328p, "PB0"); }
TEST(TimerInputCapture, BothEdgesAndTheNoiseCancelerAtmega2560) { expect_captures(kAtmega2560, "PD4"); }
TEST(TimerInputCapture, BothEdgesAndTheNoiseCancelerAtmega32) { expect_captures(kAtmega32, "PD6"); }

}  // namespace
}  // namespace avrbench::test::timers
