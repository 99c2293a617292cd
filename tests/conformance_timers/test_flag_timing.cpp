// The TCNTn value each flag comes with (firmware/conformance/timers/tmr_flag_timing).
//
// At clk/1024 the firmware reads TCNTn within a few cycles of seeing the flag,
// so inside the timer clock cycle in which the flag was set. ATmega328P
// datasheet §15.8 and §16.10 "Timer/Counter Timing Diagrams" (the same in the
// ATmega2560's §16.8, §17.10 and the ATmega32's Timer/Counter timing diagrams):
//  - OCFnx "is set in the timer clock cycle after the counter (TCNT1) value
//    matches the Output Compare Register" (§16.11.9): TCNTn = OCRnx + 1;
//  - Normal mode: "the Timer/Counter Overflow Flag (TOV1) will be set in the
//    same timer clock cycle as the TCNT1 becomes zero" (§16.9.1): 0;
//  - CTC: OCFnA is set as TCNTn goes from TOP to BOTTOM (§16.10): 0;
//  - fast PWM: TOVn, and ICFn when ICRn is TOP, set at TOP as TCNTn goes to
//    BOTTOM (§16.10: "TOVn (FPWM) and ICFn (if used as TOP)"): 0;
//  - phase correct: ICFn/OCFnA (as TOP) "set accordingly at the same timer
//    clock cycle as the OCR1x Registers are updated with the double buffer
//    value (at TOP)" (§16.9.4), as TCNTn goes TOP -> TOP-1 (§16.10): 8;
//    TOVn "is set each time the counter reaches BOTTOM": on the clock that
//    leaves BOTTOM, by the symmetry of the same diagrams (an inference: the
//    datasheet shows no BOTTOM diagram): 1; OCFnx on the down slope leaves
//    OCRnx downwards: OCRnx - 1.
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

constexpr unsigned kNotMeasured = 0xFF;

// [0] Normal OCF, OCRnA = 5: 6   [1] Normal TOV: 0   [2] CTC OCF: 0
// [3] fast PWM TOV (TOP 9): 0    [4] phase correct TOP flag (TOP 9): 8
// [5] phase correct TOV: 1       [6] OCFnB (OCRnB = 3) up: 4   [7] down: 2
// [8] the flags with TOVn in [3]: TOVn and the TOP flag (ICFn or OCFnA).
std::vector<unsigned> expected(unsigned top_flags) { return {6, 0, 0, 0, 8, 1, 4, 2, top_flags}; }

void run(const TimerPart& part, const std::vector<std::pair<std::string, std::vector<unsigned>>>& timers) {
    Mcu mcu(timer_firmware("tmr_flag_timing", part));
    while (mcu.read_ram_u8("done") == 0 && mcu.cycle() < 4'000'000) mcu.run_for(10000);
    EXPECT_EQ(mcu.read_ram_u8("done"), 1) << "a flag never came";
    for (const auto& [array, values] : timers) EXPECT_EQ(ram_words(mcu, array, 9), values) << array;
}

// TIFR1 (§16.11.9): ICF1 = bit 5, TOV1 = bit 0 -> 0x21; TIFR0/2: OCFnA = bit 1, TOVn = bit 0 -> 0x03.
TEST(TimerFlagTiming, TcntValueAtEachFlagAtmega328p) {
    run(kAtmega328p, {{"t1", expected(0x21)}, {"t0", expected(0x03)}, {"t2", expected(0x03)}});
}

// ATmega2560 TIFRn (§17.11.36..39): the same bit positions.
TEST(TimerFlagTiming, TcntValueAtEachFlagAtmega2560) {
    run(kAtmega2560, {{"t1", expected(0x21)},
                      {"t0", expected(0x03)},
                      {"t2", expected(0x03)},
                      {"t3", expected(0x21)},
                      {"t4", expected(0x21)},
                      {"t5", expected(0x21)}});
}

// ATmega32 TIFR: ICF1 = bit 5, TOV1 = bit 2 -> 0x24. Timer0/2 have only modes
// 0-3 (TOP 0xFF): [3] fast PWM TOV = 0 and [5] phase correct TOV = 1 from
// TCNTn = 0xF0; the rest is not measured there.
TEST(TimerFlagTiming, TcntValueAtEachFlagAtmega32) {
    const std::vector<unsigned> eight = {6, 0, 0, 0, kNotMeasured, 1, kNotMeasured, kNotMeasured, kNotMeasured};
    run(kAtmega32, {{"t1", expected(0x24)}, {"t0", eight}, {"t2", eight}});
}

}  // namespace
}  // namespace avrbench::test::timers
