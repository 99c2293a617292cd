// The prescaler of Timer/Counter0/1(/3/4/5) (firmware/conformance/timers/tmr_prescaler).
//
// ATmega328P datasheet §17.1: "The prescaler is free running, i.e., operates
// independently of the Clock Select logic of the Timer/Counter, and it is
// shared by Timer/Counter1 and Timer/Counter0"; "the number of system clock
// cycles from when the timer is enabled to the first count occurs can be from
// 1 to N+1 system clock cycles". §17.2 "Prescaler Reset": "It is possible to
// use the prescaler reset for synchronizing the Timer/Counter to program
// execution"; §17.4.1 GTCCR.TSM keeps PSRSYNC asserted so the timers can be
// "halted and configured to the same value without the risk of one of them
// advancing during configuration". (ATmega2560 §18; ATmega32: SFIOR.PSR10, no TSM.)
// Convention (docs/FIDELITY.md): a register write takes effect at the cycle
// its instruction starts, and a prescaler reset at cycle c gives timer clocks
// at c + k * N.
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

struct Pins {
    const char* oc1a;
    const char* oc0a;
    const char* marker2;
    const char* marker3;
};

void expect_prescaler(const TimerPart& part, const Pins& pins, bool has_tsm) {
    Mcu mcu(timer_firmware("tmr_prescaler", part));
    PinLog oc1(mcu, pins.oc1a);
    PinLog oc0(mcu, pins.oc0a);
    PinLog m2(mcu, pins.marker2);
    PinLog m3(mcu, pins.marker3);

    // A: clk/64 on both, started 13+ cycles apart: one prescaler, one phase.
    while (mcu.read_ram_u8("phase") < 1 && mcu.cycle() < 30000) mcu.run_for(10);
    ASSERT_EQ(mcu.read_ram_u8("phase"), 1);
    const auto e1 = oc1.cycles();
    const auto e0 = oc0.cycles();
    ASSERT_GE(e1.size(), 10u);
    ASSERT_GE(e0.size(), 20u);
    for (Cycle c : e0) EXPECT_EQ((c - e1[0]) % 64, 0u) << "OC0A edge at " << c << ", OC1A at " << e1[0];
    EXPECT_TRUE(all_equal(PinLog::differences(e1), 10 * 64, 9));  // (OCR1A + 1) * 64
    EXPECT_TRUE(all_equal(PinLog::differences(e0), 5 * 64, 19));  // (OCR0A + 1) * 64

    // B: PSRSYNC one cycle after the marker edge; Timer1 started 100 cycles
    // later at clk/1024 with TCNT1 = 0, OCR1A = 1: first toggle on the second
    // clock after the reset: 1 + 2 * 1024 = 2049 after the marker.
    const std::size_t before_b = oc1.edges().size();
    while (mcu.read_ram_u8("phase") < 2 && mcu.cycle() < 60000) mcu.run_for(10);
    ASSERT_EQ(m2.edges().size(), 1u);
    ASSERT_GT(oc1.edges().size(), before_b);
    EXPECT_EQ(oc1.edges()[before_b].cycle - m2.edges()[0].cycle, 2049u);

    if (!has_tsm) return;
    // C: both held by TSM, released one cycle after the marker edge; clk/8,
    // OCRnA = 9: the first toggle of each on the tenth clock, 1 + 10 * 8 = 81.
    const std::size_t before_c1 = oc1.edges().size();
    const std::size_t before_c0 = oc0.edges().size();
    mcu.run_for(2000);
    ASSERT_EQ(mcu.read_ram_u8("phase"), 3);
    ASSERT_EQ(m3.edges().size(), 1u);
    ASSERT_GT(oc1.edges().size(), before_c1);
    ASSERT_GT(oc0.edges().size(), before_c0);
    EXPECT_EQ(oc1.edges()[before_c1].cycle - m3.edges()[0].cycle, 81u);
    EXPECT_EQ(oc0.edges()[before_c0].cycle - m3.edges()[0].cycle, 81u);
}

TEST(TimerPrescaler, SharedFreeRunningResetAndSyncModeAtmega328p) {
    expect_prescaler(kAtmega328p, {"PB1", "PD6", "PC2", "PC3"}, true);
}
TEST(TimerPrescaler, SharedFreeRunningResetAndSyncModeAtmega2560) {
    expect_prescaler(kAtmega2560, {"PB5", "PB7", "PF2", "PF3"}, true);
}
TEST(TimerPrescaler, SharedFreeRunningAndResetAtmega32) {
    expect_prescaler(kAtmega32, {"PD5", "PB3", "PC2", "PC3"}, false);
}

}  // namespace
}  // namespace avrbench::test::timers
