// Seed 001's DDA as the thesis prints it (printer3d_interp_thesis_dda: Code
// 4.1-4.8, the defects of digest §3) against the fixed one
// (printer3d_interp), on the five-MCU printer. Positions: the board's 100
// BLU/mm, the carriages start at X 3.5, Y 2.5 mm (the firmware's 0).
// Intervals from the TICK strobe (PA7), 16 cycles per microsecond. The
// motion defects are found by the board's motion oracle, the timing ones
// measured here; each test runs under ctest's wall-clock limit.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "parts/MotionOracle.hpp"
#include "printer3d/PrinterBench.hpp"
#include "support/PinLog.hpp"

namespace avrbench {
namespace thesis_dda_test {

constexpr double kCyclesPerUs = 16.0;
const char* const kLiteral = "printer3d_interp_thesis_dda";

std::unique_ptr<Bench> run_job(const std::string& interp, const std::string& job) {
    auto bench = test::powered_printer(interp);
    bench->run_for(0.2);
    bench->host().add_lines(job);
    EXPECT_EQ(bench->run_until_idle(30.0), IdleResult::Idle);
    return bench;
}

// The motion oracle's findings of one kind about a line ("line 1 'G1 X3 F600'").
std::vector<std::string> oracle_findings(Bench& bench, FindingKind kind, const std::string& line) {
    std::vector<std::string> out;
    for (const Finding& f : bench.findings()) {
        if (f.kind == kind && f.detail.find(line) != std::string::npos) out.push_back(f.detail);
    }
    return out;
}

double number_after(const std::string& detail, const std::string& before) {
    const auto at = detail.find(before);
    return at == std::string::npos ? NAN : std::stod(detail.substr(at + before.size()));
}

// Code 4.1: L = round(sqrt(_a*_a + _b*_b)) in 16-bit ints. X3 is 300 BLU:
// 300^2 = 90 000 = 65 536 + 24 464, sqrt(24 464) = 156.4, L = 156 ticks of
// at most one pulse each: 156 X steps, 1.56 mm of the 3.
TEST(Printer3dThesisDda, SixteenBitLStopsALongLineShort) {
    auto literal = run_job(kLiteral, "G1 X3 F600\nM400\n");
    EXPECT_NEAR(literal->axis("x").position_mm(), 3.5 + 1.56, 0.01);
    const auto missed = oracle_findings(*literal, MotionOracle::kMoveEndMissed, "line 1 'G1 X3 F600'");
    ASSERT_EQ(missed.size(), 1u);
    EXPECT_NEAR(number_after(missed[0], "came to rest "), 3.0 - 1.56, 0.01) << missed[0];

    auto fixed = run_job("printer3d_interp", "G1 X3 F600\nM400\n");
    EXPECT_NEAR(fixed->axis("x").position_mm(), 3.5 + 3.0, 0.01);
    for (const Finding& f : fixed->findings()) ADD_FAILURE() << f.describe();
}

// Code 4.6: s = 2 R arcsin(AB / 2R). A 270-degree arc (centre (-1, 0), R 1
// mm = 100 BLU, from (0, 0) counter-clockwise to (-1, -1)) has the chord of
// a 90-degree one, sqrt(2) mm: s = 2 * 100 * pi/4 = 157 ticks, a quarter
// circle to (-1, 1), 2 mm from its end. A whole circle has AB = 0: no tick.
// F500 (dt_c = 1200 us): below the dt profile's own 16-bit wrap (above 1310
// us), and slow enough that the fixed build's motors follow an arc this
// tight (at F600 they slip 4 steps on it: motor-stall).
TEST(Printer3dThesisDda, ArcsinArcLengthStopsLongArcsAndSkipsCircles) {
    auto literal = run_job(kLiteral, "G3 X-1 Y-1 I-1 J0 F500\nM400\n");
    EXPECT_NEAR(literal->axis("x").position_mm(), 3.5 - 1.0, 0.01);
    EXPECT_NEAR(literal->axis("y").position_mm(), 2.5 + 1.0, 0.01);
    const auto missed = oracle_findings(*literal, MotionOracle::kMoveEndMissed, "line 1 'G3 X-1 Y-1 I-1 J0 F500'");
    ASSERT_EQ(missed.size(), 1u);
    EXPECT_NEAR(number_after(missed[0], "came to rest "), 2.0, 0.01) << missed[0];

    auto circle = run_job(kLiteral, "G2 X0 Y0 I-1 J0 F500\nG1 X0.5 F500\nM400\n");
    const auto skipped = oracle_findings(*circle, MotionOracle::kMoveEndMissed, "line 1 'G2 X0 Y0 I-1 J0 F500'");
    ASSERT_EQ(skipped.size(), 1u);
    EXPECT_NE(skipped[0].find("after 0.000 of its 6.283 mm"), std::string::npos) << skipped[0];  // 2 pi R

    for (const std::string job : {"G3 X-1 Y-1 I-1 J0 F500\nM400\n", "G2 X0 Y0 I-1 J0 F500\nG1 X0.5 F500\nM400\n"}) {
        auto fixed = run_job("printer3d_interp", job);
        for (const Finding& f : fixed->findings()) ADD_FAILURE() << job << f.describe();
    }
}

// The interval before tick n (us), from the TICK strobe's rises.
std::vector<double> tick_intervals_us(const std::string& interp, const std::string& job) {
    auto bench = test::powered_printer(interp);
    bench->run_for(0.2);
    test::PinLog tick(bench->mcu("interp"), "PA7");
    bench->host().add_lines(job);
    EXPECT_EQ(bench->run_until_idle(30.0), IdleResult::Idle);
    std::vector<double> before{NAN, NAN};  // ticks 0 and 1 have none
    const auto& r = tick.rises();
    for (std::size_t i = 1; i < r.size(); ++i) before.push_back(static_cast<double>(r[i] - r[i - 1]) / kCyclesPerUs);
    return before;
}

// Code 4.7-4.8 with N = 50 in 16-bit unsigned ints:
//   n < N: dt = N dt_c / n;  n > total - N: dt = N dt_c / (total - n + 1);  else dt_c.
TEST(Printer3dThesisDda, TheDtProfilesSixteenBitDefects) {
    // 30 ticks at F600 (dt_c = 1000 us): total - N wraps, so the ramp never
    // comes down: before the last tick N dt_c / 30 = 1666 us where the fixed
    // profile has N dt_c / 1 = 50 000 us.
    const auto short_literal = tick_intervals_us(kLiteral, "G1 X0.3 F600\nM400\n");
    const auto short_fixed = tick_intervals_us("printer3d_interp", "G1 X0.3 F600\nM400\n");
    ASSERT_EQ(short_literal.size(), 31u);
    ASSERT_EQ(short_fixed.size(), 31u);
    EXPECT_NEAR(short_literal[30], 50000 / 30, 2);
    EXPECT_NEAR(short_fixed[30], 50000, 2);
    // 60 ticks: the ramps overlap and the first wins: tick 40 is still
    // accelerating, 50 000 / 40 = 1250 us, where the fixed profile is already
    // 21 ticks from the end, 50 000 / 21 = 2381 us.
    const auto overlap_literal = tick_intervals_us(kLiteral, "G1 X0.6 F600\nM400\n");
    const auto overlap_fixed = tick_intervals_us("printer3d_interp", "G1 X0.6 F600\nM400\n");
    ASSERT_EQ(overlap_literal.size(), 61u);
    ASSERT_EQ(overlap_fixed.size(), 61u);
    EXPECT_NEAR(overlap_literal[40], 1250, 2);
    EXPECT_NEAR(overlap_fixed[40], 50000.0 / 21, 2);
    // F300: dt_c = 2000 us, and N dt_c = 100 000 wraps to 34 464: before tick
    // 2, 34 464 / 2 = 17 232 us where the fixed profile waits 50 000.
    const auto slow_literal = tick_intervals_us(kLiteral, "G1 X1 F300\nM400\n");
    const auto slow_fixed = tick_intervals_us("printer3d_interp", "G1 X1 F300\nM400\n");
    ASSERT_GE(slow_literal.size(), 3u);
    ASSERT_GE(slow_fixed.size(), 3u);
    EXPECT_NEAR(slow_literal[2], 17232, 2);
    EXPECT_NEAR(slow_fixed[2], 50000, 2);
}

}  // namespace thesis_dda_test
}  // namespace avrbench
