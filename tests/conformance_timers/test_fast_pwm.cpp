// Fast PWM (firmware/conformance/timers/tmr_fast_pwm).
//
// ATmega328P datasheet §15.7.3, §16.9.3, §18.7.3 (ATmega2560 §16.7.3,
// §17.9.3, §20.7.3; ATmega32 "Fast PWM Mode"): the counter runs BOTTOM..TOP,
// so a period is (TOP + 1) * N cycles; non-inverting (COMnx = 10, Tables 15-3,
// 16-2, 18-3) clears OCnx on the compare match and sets it at BOTTOM, so OCnx
// is high for (OCRnx + 1) * N cycles (inverting, 11: low that long). "If the
// OCR0A is set equal to BOTTOM, the output will be a narrow spike for each
// MAX+1 timer clock cycle. Setting the OCR0A equal to MAX will result in a
// constantly high or low output"; a compare value above TOP never matches
// (§16.9.3: "a compare match will never occur"). COM1A = 01 with OCR1A as TOP
// toggles OC1A on every match (Table 16-2, modes 14/15). OCRnx is double
// buffered: "Update of OCRx at BOTTOM" (Tables 15-8, 16-4).
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

struct Pwm {
    const char* pin;
    Cycle period;  // (TOP + 1) * N
    Cycle high;    // cycles high per period; 0: constantly low, == period: constantly high
};

void expect_pwm(const PinLog& log, const Pwm& p) {
    SCOPED_TRACE(p.pin);
    if (p.high == 0 || p.high == p.period) {
        // Constant: at most the first set at BOTTOM, then no edge at all.
        EXPECT_LE(log.edges().size(), 1u);
        if (!log.edges().empty()) {
            EXPECT_EQ(log.edges().back().level, p.high != 0);
        }
        return;
    }
    const std::size_t n = 12000 / p.period;
    EXPECT_TRUE(all_equal(PinLog::differences(log.rises()), p.period, n - 2));
    EXPECT_TRUE(all_equal(log.high_times(), p.high, n - 2));
}

// OC1A: 250 high of 1000 (OCR1A = 249) until the firmware writes OCR1A = 99 at
// TCNT1 >= 150; the period in progress keeps its 250 (the new value waits in
// the buffer until BOTTOM), the following ones are 100 high.
void expect_double_buffer(const PinLog& oc1a) {
    const auto highs = oc1a.high_times();
    std::size_t i = 0;
    while (i < highs.size() && highs[i] == 250) ++i;
    EXPECT_GE(i, 4u);
    std::vector<Cycle> rest(highs.begin() + static_cast<std::ptrdiff_t>(i), highs.end());
    EXPECT_TRUE(all_equal(rest, 100, 5)) << "high times after OCR1A = 99 (250 before)";
}

void run_pwm(const TimerPart& part, const std::vector<Pwm>& pwms, const char* oc1a) {
    Mcu mcu(timer_firmware("tmr_fast_pwm", part));
    std::vector<std::unique_ptr<PinLog>> logs;
    for (const auto& p : pwms) logs.push_back(std::make_unique<PinLog>(mcu, p.pin));
    PinLog oc1(mcu, oc1a);
    mcu.run_for(12000);
    for (std::size_t i = 0; i < pwms.size(); ++i) expect_pwm(*logs[i], pwms[i]);
    while (mcu.read_ram_u8("phase") == 0 && mcu.cycle() < 20000) mcu.run_for(100);
    mcu.run_for(10000);
    expect_double_buffer(oc1);
}

TEST(TimerFastPwm, DutyBottomTopAndDoubleBufferAtmega328p) {
    run_pwm(kAtmega328p,
            {{"PD6", 256, 1},     // OC0A, OCR0A = 0: narrow spike, one timer clock
             {"PD5", 256, 64},    // OC0B, OCR0B = 63
             {"PB3", 256, 256},   // OC2A, OCR2A = 255 = TOP: constantly high
             {"PD3", 256, 64},    // OC2B inverting, OCR2B = 191: low 192, high 256 - 192
             {"PB2", 1000, 1}},   // OC1B, OCR1B = 0, TOP = ICR1 = 999
            "PB1");
}

TEST(TimerFastPwm, DutyBottomTopAndDoubleBufferAtmega2560) {
    run_pwm(kAtmega2560,
            {{"PB7", 256, 1},
             {"PG5", 256, 64},
             {"PB4", 256, 256},
             {"PH6", 256, 64},
             {"PB6", 1000, 1},
             {"PE4", 400, 100},    // OC3B, TOP = OCR3A = 399, OCR3B = 99
             {"PH3", 256, 128},    // OC4A, mode 5 (8-bit), OCR4A = 127
             {"PH4", 256, 0},      // OC4B inverting, OCR4B = 300 > TOP: cleared at BOTTOM only
             {"PL3", 1024, 0},     // OC5A inverting, OCR5A = 0x3FF = TOP: constantly low
             {"PL4", 1024, 512}},  // OC5B, mode 7 (10-bit), OCR5B = 511
            "PB5");
}

TEST(TimerFastPwm, ToggleOnMatchWithOcraAsTopAtmega2560) {
    // Table 17-3 (2560; 328P Table 16-2): WGMn3:0 = 15, COMnA = 01: "Toggle OCnA
    // on Compare Match": every (OCR3A + 1) * 1 = 400 cycles.
    Mcu mcu(timer_firmware("tmr_fast_pwm", kAtmega2560));
    PinLog oc3a(mcu, "PE3");
    mcu.run_for(12000);
    EXPECT_TRUE(all_equal(oc3a.intervals(), 400, 25));
}

TEST(TimerFastPwm, DutyBottomTopAndDoubleBufferAtmega32) {
    run_pwm(kAtmega32, {{"PB3", 256, 64}, {"PD4", 1000, 1}}, "PD5");
}

TEST(TimerFastPwm, Seed001HeaterPwmOnTimer2Atmega32) {
    // The seed 001 heater output: Timer2 fast PWM, clk/128, OC2 (PD7)
    // non-inverting; period 256 * 128 = 32768 cycles. The firmware writes OCR2
    // = 255 just after the 3rd TOV2 (BOTTOM B3) and 127 just after the 6th
    // (B6); each takes effect at the next BOTTOM (B4, B7).
    //  - OCR2 = 0: a spike of one timer clock, 128 cycles, every period;
    //  - OCR2 = 255: constantly high from B4 (set at BOTTOM, never cleared);
    //  - OCR2 = 127: high (127 + 1) * 128 = 16384 of 32768.
    // So the pin is high once for 3 * 32768 + 16384 = 114688 cycles (B4 to
    // B7 + 16384) between the 128s and the 16384s.
    Mcu mcu(timer_firmware("tmr_fast_pwm", kAtmega32));
    PinLog oc2(mcu, "PD7");
    while (mcu.read_ram_u8("phase") != 2 && mcu.cycle() < 400000) mcu.run_for(1000);
    ASSERT_EQ(mcu.read_ram_u8("phase"), 2);
    mcu.run_for(5 * 32768);
    const auto highs = oc2.high_times();
    std::size_t i = 0;
    while (i < highs.size() && highs[i] == 128) ++i;
    EXPECT_GE(i, 3u) << "spikes of 128 while OCR2 = 0";
    ASSERT_LT(i, highs.size());
    EXPECT_EQ(highs[i], 114688u);
    std::vector<Cycle> rest(highs.begin() + static_cast<std::ptrdiff_t>(i) + 1, highs.end());
    EXPECT_TRUE(all_equal(rest, 16384, 3));
    // Rises at BOTTOM only: 32768 apart, but for the constant-high stretch.
    const auto rises = oc2.rises();
    for (std::size_t k = 1; k < rises.size(); ++k) EXPECT_EQ((rises[k] - rises[0]) % 32768, 0u) << "rise " << k;
}

}  // namespace
}  // namespace avrbench::test::timers
