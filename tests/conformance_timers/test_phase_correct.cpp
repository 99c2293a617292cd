// Phase correct and phase and frequency correct PWM
// (firmware/conformance/timers/tmr_phase_correct).
//
// ATmega328P datasheet §15.7.4, §16.9.4, §16.9.5, §18.7.4 (ATmega2560
// §16.7.4, §17.9.4, §17.9.5, §20.7.4; ATmega32 "Phase Correct PWM Mode"):
// dual slope, the counter runs BOTTOM -> TOP -> BOTTOM, one period is
// 2 * TOP timer clocks ("f_OCnxPCPWM = f_clk_I/O / (N * 510)" for TOP = 0xFF).
// Non-inverting (COMnx = 10, Tables 15-4, 16-3, 18-4) clears OCnx on the
// up-counting match and sets it on the down-counting one, so OCnx is high for
// 2 * OCRnx clocks per period; "If the OCR0A register is written equal to
// BOTTOM, the output will be continuously low. If OCR0A is written to MAX,
// the output will be continuously high for non-inverted PWM mode. For
// inverted PWM the output will have the opposite logic values." COM1A = 01
// with OCR1A as TOP (modes 9, 11) toggles OC1A on the match, i.e. at TOP.
// OCRnx is double buffered, "Update of OCR1x at TOP" (Table 16-4, modes 10, 11).
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace phase_correct_test {

struct Pwm {
    const char* pin;
    Cycle period;  // 2 * TOP * N
    Cycle high;    // 0: continuously low; == period: continuously high
};

void expect_pwm(const PinLog& log, const Pwm& p, Cycle run) {
    SCOPED_TRACE(p.pin);
    if (p.high == 0 || p.high == p.period) {
        EXPECT_LE(log.edges().size(), 1u);
        if (!log.edges().empty()) {
            EXPECT_EQ(log.edges().back().level, p.high != 0);
        }
        return;
    }
    const std::size_t n = run / p.period;
    EXPECT_TRUE(all_equal(PinLog::differences(log.rises()), p.period, n - 2));
    EXPECT_TRUE(all_equal(log.high_times(), p.high, n - 2));
}

// OC1A, TOP = ICR1 = 500: high 2 * 100 = 200 of 1000 until the firmware writes
// OCR1A = 400 on a down slope at TCNT1 <= 200. The buffer reaches OCR1A at the
// next TOP: that period still sets at 100 (down) and clears at 100 (up), then
// high 2 * 400 = 800. Low: 2 * (500 - 100) = 800, then once from the up match at
// 100 to the down match at 400: (500 - 100) + (500 - 400) = 500, then
// 2 * (500 - 400) = 200.
void expect_double_buffer(const PinLog& oc1a) {
    const auto highs = oc1a.high_times();
    std::size_t i = 0;
    while (i < highs.size() && highs[i] == 200) ++i;
    EXPECT_GE(i, 4u);
    EXPECT_TRUE(all_equal(std::vector<Cycle>(highs.begin() + static_cast<std::ptrdiff_t>(i), highs.end()), 800, 4))
        << "high times after OCR1A = 400 (200 before)";
    const auto lows = oc1a.low_times();
    std::size_t j = 0;
    while (j < lows.size() && lows[j] == 800) ++j;
    ASSERT_LT(j, lows.size());
    EXPECT_EQ(lows[j], 500u);
    EXPECT_TRUE(all_equal(std::vector<Cycle>(lows.begin() + static_cast<std::ptrdiff_t>(j) + 1, lows.end()), 200, 3));
}

void run_pwm(const TimerPart& part, const std::vector<Pwm>& pwms, const char* oc1a) {
    Mcu mcu(timer_firmware("tmr_phase_correct", part));
    std::vector<std::unique_ptr<PinLog>> logs;
    for (const auto& p : pwms) logs.push_back(std::make_unique<PinLog>(mcu, p.pin));
    PinLog oc1(mcu, oc1a);
    constexpr Cycle kRun = 14000;
    mcu.run_for(kRun);
    EXPECT_EQ(mcu.read_ram_u8("phase"), 1) << "ICF1 never seen at TOP";
    for (std::size_t i = 0; i < pwms.size(); ++i) expect_pwm(*logs[i], pwms[i], kRun);
    expect_double_buffer(oc1);
}

TEST(TimerPhaseCorrectPwm, DutyBottomTopAndDoubleBufferAtmega328p) {
    run_pwm(kAtmega328p,
            {{"PD6", 510, 0},     // OC0A, OCR0A = 0 = BOTTOM: continuously low
             {"PD5", 510, 510},   // OC0B, OCR0B = 255 = MAX: continuously high
             {"PB3", 510, 128},   // OC2A, OCR2A = 64: 2 * 64
             {"PB2", 1000, 1000}},  // OC1B, OCR1B = 500 = TOP: continuously high
            "PB1");
}

TEST(TimerPhaseCorrectPwm, InvertingOutputAtmega328p) {
    // OC2B, COM2B = 11, OCR2B = 64: low 2 * 64 = 128 of 510.
    Mcu mcu(timer_firmware("tmr_phase_correct", kAtmega328p));
    PinLog oc2b(mcu, "PD3");
    mcu.run_for(10000);
    EXPECT_TRUE(all_equal(PinLog::differences(oc2b.falls()), 510, 15));
    EXPECT_TRUE(all_equal(oc2b.low_times(), 128, 15));
}

TEST(TimerPhaseCorrectPwm, DutyBottomTopAndDoubleBufferAtmega2560) {
    run_pwm(kAtmega2560,
            {{"PB7", 510, 0},
             {"PG5", 510, 510},
             {"PB4", 510, 128},
             {"PB6", 1000, 1000},
             {"PE3", 600, 300},    // OC3A, phase and frequency correct, TOP = ICR3 = 300, OCR3A = 150
             {"PH4", 400, 100},    // OC4B, TOP = OCR4A = 200, OCR4B = 50
             {"PL3", 510, 256}},   // OC5A, mode 1 (8-bit), OCR5A = 128
            "PB5");
}

TEST(TimerPhaseCorrectPwm, ToggleAtTopWithOcraAsTopAtmega2560) {
    // Timer4 mode 11, COM4A = 01: OC4A toggles on the match with OCR4A = TOP =
    // 200, once per period of 2 * 200 = 400 cycles.
    Mcu mcu(timer_firmware("tmr_phase_correct", kAtmega2560));
    PinLog oc4a(mcu, "PH3");
    mcu.run_for(10000);
    EXPECT_TRUE(all_equal(oc4a.intervals(), 400, 20));
}

TEST(TimerPhaseCorrectPwm, DutyBottomTopAndDoubleBufferAtmega32) {
    run_pwm(kAtmega32,
            {{"PB3", 510, 128},    // OC0, OCR0 = 64
             {"PD7", 510, 0},      // OC2, OCR2 = 0: continuously low
             {"PD4", 1000, 1000}},
            "PD5");
}

}  // namespace phase_correct_test
}  // namespace avrbench::test::timers
