// Normal mode and the other clock sources (firmware/conformance/timers/
// tmr_normal, tmr_clock_sources).
//
// ATmega328P datasheet §15.7.1, §16.9.1, §18.7.1 (ATmega2560 §16.7.1,
// §17.9.1, §20.7.1; ATmega32 "Normal Mode"): the counter counts up from
// BOTTOM to MAX and "simply overruns when it passes its maximum ... value and
// then restarts from the bottom": a compare match, and the OCnA toggle
// (COMnA = 01), every (MAX + 1) * N cycles; TOVn once per wrap, so the
// TIMER0_OVF vector runs every 256 cycles at clk/1.
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace normal_test {

struct Channel {
    const char* pin;
    Cycle interval;  // (MAX + 1) * N
};

void expect_normal(const TimerPart& part, const std::vector<Channel>& channels, Cycle run) {
    Mcu mcu(timer_firmware("tmr_normal", part));
    std::vector<std::unique_ptr<PinLog>> logs;
    for (const auto& c : channels) logs.push_back(std::make_unique<PinLog>(mcu, c.pin));
    const Cycle start = mcu.cycle();
    mcu.run_for(run);
    for (std::size_t i = 0; i < channels.size(); ++i) {
        EXPECT_TRUE(all_equal(logs[i]->intervals(), channels[i].interval, run / channels[i].interval - 2))
            << channels[i].pin;
    }
    // One TIMER0_OVF per 256 cycles since Timer0 started (a few cycles after reset).
    const Cycle expected = (mcu.cycle() - start) / 256;
    EXPECT_GE(mcu.read_ram_u16("overflows") + 1u, expected);
    EXPECT_LE(mcu.read_ram_u16("overflows"), expected);
}

// Timer0: 256 * 1; Timer1: 65536 * 1; Timer2: 256 * 8 = 2048.
TEST(TimerNormal, WrapsAtMaxAtmega328p) {
    expect_normal(kAtmega328p, {{"PD6", 256}, {"PB1", 65536}, {"PB3", 2048}}, 300000);
}

// + Timer3: 65536 * 1; Timer4: 65536 * 8 = 524288; Timer5: 65536 * 1.
TEST(TimerNormal, WrapsAtMaxAtmega2560) {
    expect_normal(kAtmega2560,
                  {{"PB7", 256}, {"PB5", 65536}, {"PB4", 2048}, {"PE3", 65536}, {"PH3", 524288}, {"PL3", 65536}},
                  2200000);
}

TEST(TimerNormal, WrapsAtMaxAtmega32) {
    expect_normal(kAtmega32, {{"PB3", 256}, {"PD5", 65536}, {"PD7", 2048}}, 300000);
}

TEST(TimerClockSource, Timer2FromThe32kHzCrystalAtmega328p) {
    // §18.9: AS2 = 1 clocks Timer2 from TOSC1 (32768 Hz); Normal mode, N = 1:
    // an OC2A toggle every 256 crystal periods = 256 * 16e6 / 32768 = 125000 cycles.
    Mcu mcu(timer_firmware("tmr_clock_sources", kAtmega328p));
    PinLog oc2a(mcu, "PB3");
    mcu.run_for(700000);
    EXPECT_TRUE(all_equal(oc2a.intervals(), 125000, 4));
}

TEST(TimerClockSource, Timer1CountsRisingEdgesOnT1Atmega328p) {
    // §17.3: CS12:0 = 111: Timer1 counts rising edges on T1 (PD5). CTC with
    // OCR1A = 9: OC1A toggles on the 10th and 20th edge; after 25, TCNT1 = 5.
    Mcu mcu(timer_firmware("tmr_clock_sources", kAtmega328p));
    PinLog oc1a(mcu, "PB1");
    Pin& t1 = mcu.pin("PD5");
    t1.drive(false);
    mcu.run_for(1000);
    std::vector<Cycle> rises;
    for (int i = 0; i < 25; ++i) {
        t1.drive(true);
        rises.push_back(mcu.cycle());
        mcu.run_for(20);
        t1.drive(false);
        mcu.run_for(20);
    }
    mcu.run_for(100);
    ASSERT_EQ(oc1a.edges().size(), 2u);
    EXPECT_EQ(oc1a.edges()[0].cycle, rises[9]);
    EXPECT_EQ(oc1a.edges()[1].cycle, rises[19]);
    EXPECT_EQ(mcu.read_ram_u16("tcnt1"), 5);
}

}  // namespace normal_test
}  // namespace avrbench::test::timers
