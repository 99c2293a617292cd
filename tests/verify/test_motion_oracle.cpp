// The motion oracle (parts/MotionOracle) and the G-code reading that feeds it
// (run/CommandedPath): what the accepted lines command, by hand, and the
// seed systems' wrong motion reported by the run (issue 40 item 1). Each run
// here is bounded in simulated time; ctest's limit is the wall-clock guard.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cam/Chain.hpp"
#include "cam/DxfReader.hpp"
#include "cam/Records.hpp"
#include "boards/BoardFile.hpp"
#include "parts/Axis.hpp"
#include "parts/MotionOracle.hpp"
#include "printer3d/PrinterBench.hpp"
#include "support/Paths.hpp"
#include "run/Bench.hpp"
#include "run/BoardRun.hpp"
#include "run/CommandedPath.hpp"

namespace avrbench {
namespace {

// What the G-code reading tells a judge, as text.
struct Recorded final : CommandedMoves {
    std::vector<CommandedMove> moves;
    std::vector<std::pair<AxisPositions, AxisPositions>> renames;
    std::vector<std::string> lost;
    SoftLimits limits{};
    SoftLimits soft_limits_mm() const override { return limits; }
    void commanded(const CommandedMove& m) override { moves.push_back(m); }
    void position_renamed(const AxisPositions& was, const AxisPositions& now) override { renames.push_back({was, now}); }
    void frame_lost(const std::string& line, const std::string&) override { lost.push_back(line); }
    bool retract(std::size_t n, bool) override {
        moves.resize(moves.size() - std::min(n, moves.size()));
        return true;
    }
};

void feed(CommandedPath& path, const std::vector<std::string>& lines) {
    for (const auto& l : lines) path.accept(l, "'" + l + "'");
}

TEST(CommandedPath, AbsoluteRelativeAndInchMovesFromTheFirmwaresZero) {
    Recorded r;
    CommandedPath path(r);
    feed(path, {"G21 G90", "G1 X10 Y5 F600", "G1 F1200", "G91", "G0 X-2.5 Y1", "G20 G90", "G1 X1"});
    ASSERT_EQ(r.moves.size(), 3u);  // G1 F1200 moves nothing
    EXPECT_EQ(r.moves[0].kind, CommandedMove::Kind::Feed);
    EXPECT_EQ(r.moves[0].from_mm, (AxisPositions{0.0, 0.0, 0.0}));
    EXPECT_EQ(r.moves[0].to_mm, (AxisPositions{10.0, 5.0, 0.0}));
    EXPECT_EQ(r.moves[1].kind, CommandedMove::Kind::Rapid);
    EXPECT_EQ(r.moves[1].to_mm, (AxisPositions{7.5, 6.0, 0.0}));  // 10 - 2.5, 5 + 1
    EXPECT_EQ(r.moves[2].to_mm, (AxisPositions{25.4, 6.0, 0.0}));  // 1 inch
    EXPECT_TRUE(r.lost.empty());
}

TEST(CommandedPath, ArcCentresByOffsetsAndByRadius) {
    // From (0, 0) to (1, 1) with R 1: the centres at distance 1 from both
    // ends are (1, 0) and (0, 1). Clockwise the short way turns about (1, 0)
    // (180 deg to 90 deg); counter-clockwise about (0, 1); a negative R
    // takes the long way, about the other one.
    const auto centre = [](const std::string& arc) {
        Recorded r;
        CommandedPath path(r);
        feed(path, {arc});
        EXPECT_EQ(r.moves.size(), 1u) << arc;
        return r.moves.empty() ? std::array<double, 2>{NAN, NAN} : r.moves[0].centre_mm;
    };
    const auto near = [](std::array<double, 2> c, double x, double y) { return std::abs(c[0] - x) < 1e-12 && std::abs(c[1] - y) < 1e-12; };
    EXPECT_TRUE(near(centre("G2 X1 Y1 R1"), 1, 0));
    EXPECT_TRUE(near(centre("G3 X1 Y1 R1"), 0, 1));
    EXPECT_TRUE(near(centre("G2 X1 Y1 R-1"), 0, 1));
    EXPECT_TRUE(near(centre("G2 X10 Y0 I5 J0"), 5, 0));
    EXPECT_TRUE(near(centre("G3 X0 Y0 I-8 J0"), -8, 0));  // a whole circle, back to its start
}

TEST(CommandedPath, HomingRenamingAndLinesThatLoseTheFrame) {
    Recorded r;
    CommandedPath path(r);
    feed(path, {"G1 X10 Y4", "G28 X0", "G92 Y1.5", "G1 X2"});
    ASSERT_EQ(r.moves.size(), 3u);
    EXPECT_EQ(r.moves[1].kind, CommandedMove::Kind::Home);
    EXPECT_EQ(r.moves[1].homed, (std::array<bool, 3>{true, false, false}));
    EXPECT_EQ(r.moves[1].to_mm, (AxisPositions{0.0, 4.0, 0.0}));
    ASSERT_EQ(r.renames.size(), 1u);
    EXPECT_EQ(r.renames[0].first, (AxisPositions{std::nullopt, 4.0, std::nullopt}));
    EXPECT_EQ(r.renames[0].second, (AxisPositions{std::nullopt, 1.5, std::nullopt}));
    EXPECT_EQ(r.moves[2].from_mm, (AxisPositions{0.0, 1.5, 0.0}));
    // Lines every firmware does not read alike: nothing after them is judged.
    for (const std::string& line : std::vector<std::string>{"X10", "G1 X1E3", "G54", "g1 x1", "$H", "G0 G1 X1",
                                                            "G2 X1 Y1", "G1 X" + std::string(400, '9')}) {
        Recorded lost;
        CommandedPath p(lost);
        feed(p, {line, "G1 X5"});
        EXPECT_EQ(lost.lost.size(), 1u) << line;
        EXPECT_TRUE(lost.moves.empty()) << line;
    }
}

// Marlin 1.1.9's software endstops (Configuration.h: X 0..X_BED_SIZE 200,
// Y 0..200, Z 0..Z_MAX_POS 135 in tonyj321's tree): clamp_to_software_endstops
// puts a line's end on them axis by axis, so G1 X-1 from 0 moves nothing and
// G1 X250 Y50 ends at X200 Y50. An arc that crosses one is clamped segment
// by segment: its path is no circle, so it is not judged (the Marlin
// campaign's G3 X0 J4 from (0, 0): a circle about (0, 4) through X -4).
TEST(CommandedPath, SoftwareEndstopsClampALinesEndAndStopTheJudgingOfAnArcThatCrossesThem) {
    Recorded r;
    r.limits = {{{0.0, 200.0}, {0.0, 200.0}, {0.0, 135.0}}};
    CommandedPath path(r);
    feed(path, {"G1 X-1", "G1 X250 Y50 Z200", "G91", "G1 X10", "G90", "G2 X190 Y50 I-5 J0"});
    ASSERT_EQ(r.moves.size(), 2u);  // G1 X-1 and the relative X10 from X200 end where they start
    EXPECT_EQ(r.moves[0].to_mm, (AxisPositions{200.0, 50.0, 135.0}));
    EXPECT_EQ(r.moves[1].kind, CommandedMove::Kind::ArcClockwise);  // about (195, 50), R 5: inside
    EXPECT_TRUE(r.lost.empty());
    feed(path, {"G1 X5 Y5", "G3 X5 Y5 I0 J4"});  // about (5, 9), R 4: X from 1 to 9, Y from 5 to 13
    EXPECT_TRUE(r.lost.empty());
    feed(path, {"G1 X0 Y0", "G3 X0 Y0 I0 J4"});  // about (0, 4): X down to -4
    ASSERT_EQ(r.lost.size(), 1u);
    EXPECT_EQ(r.lost[0], "'G3 X0 Y0 I0 J4'");
    Recorded renamed;
    renamed.limits = r.limits;
    CommandedPath p2(renamed);
    feed(p2, {"G92 X10"});
    EXPECT_EQ(renamed.lost.size(), 1u);
}

// Seed 002's plot job as `avrbench run --dxf` makes it (bench/tools/RunCommand.cpp).
BoardRunOptions::RecordJob plot_job(const std::string& dxf, bool improved) {
    Drawing drawing = read_dxf(dxf).drawing;
    align_segments(drawing, 0.01);
    const GcodeProgram gcode = emit_gcode(drawing, 0.01, 120);
    RecordOptions options;
    options.improved = improved;
    const RecordProgram program = records_from_gcode(gcode.text, options, dxf);
    return {dxf, improved ? "improved" : "faithful", program.messages, program.busy_seconds, gcode.text};
}

struct PlotRun {
    std::unique_ptr<BoardRun> run;
    std::vector<Finding> findings;
    double y_end_mm = 0;
};

PlotRun plot_example(bool improved) {
    BoardRunOptions o;
    o.board = test::source_path("bench/boards/cnc2axis-seed002.yaml");
    o.firmware = {{"uno", test::firmware(improved ? "cnc2axis_improved" : "cnc2axis")}};
    o.duration_ps = 200'000 * kPsPerMs;  // the job takes ~106 s at 2 mm/s
    const std::string dxf = test::source_path("examples/drawings/plotter_demo.dxf");
    o.records = [dxf, improved] { return plot_job(dxf, improved); };
    PlotRun p;
    p.run = std::make_unique<BoardRun>(std::move(o));
    p.run->run();
    p.findings = p.run->bench().findings();
    p.y_end_mm = p.run->bench().axis("y").position_mm();
    return p;
}

std::vector<const Finding*> of_kind(const std::vector<Finding>& all, FindingKind kind) {
    std::vector<const Finding*> out;
    for (const Finding& f : all) {
        if (f.kind == kind) out.push_back(&f);
    }
    return out;
}

// The number a finding's detail gives after `before` ("strays 0.759 mm").
double number_after(const std::string& detail, const std::string& before) {
    const auto at = detail.find(before);
    if (at == std::string::npos) return NAN;
    return std::stod(detail.substr(at + before.size()));
}

// The drawing (examples/drawings/plotter_demo.dxf) through the CAM: line 8
// is the rapid "G00 X48.000 Y40.000" to the circle, line 9 the circle
// "G02 X48.000 Y40.000 I-8.000 J0.000" (R 8 about (40, 40)).
TEST(MotionOracle, SeedTwosFaithfulPlotIsOffAndTheImprovedOneIsNot) {
    const PlotRun faithful = plot_example(false);
    // The thesis' G01 counts X only and lets Y run open loop at its own
    // OCR2A rate (digest §7.7), so Y ends off its target; the thesis'
    // firmware lowers and lifts the pen without waiting for the servo, so
    // the pen drags into the next rapid (docs/CNC.md).
    const auto deviations = of_kind(faithful.findings, MotionOracle::kPathDeviation);
    bool circle_off = false;
    for (const Finding* f : deviations) {
        if (f->detail.find("line 9 'G02 X48.000 Y40.000 I-8.000 J0.000") == std::string::npos) continue;
        circle_off = true;
        EXPECT_GT(number_after(f->detail, "strays "), 0.5) << f->detail;  // the board's path_tolerance
    }
    EXPECT_TRUE(circle_off) << "no path-deviation on the circle";
    // At rest after the circle: Y where the axis part says it is, against
    // the commanded 40 mm (the firmware's zero is the homed 0 mm).
    bool rest_off = false;
    for (const Finding* f : of_kind(faithful.findings, MotionOracle::kMoveEndMissed)) {
        if (f->detail.find("line 9 ") == std::string::npos || f->detail.find("came to rest") == std::string::npos) continue;
        rest_off = true;
        EXPECT_NEAR(number_after(f->detail, "came to rest "), std::abs(faithful.y_end_mm - 40.0), 0.001) << f->detail;
    }
    EXPECT_TRUE(rest_off) << "no move-end-missed at the end";
    EXPECT_GT(std::abs(faithful.y_end_mm - 40.0), 1.0 / 160);  // more than one microstep
    bool dragged = false;
    for (const Finding* f : of_kind(faithful.findings, MotionOracle::kToolDownOffPath)) {
        dragged = dragged || f->detail.find("line 8 'G00 X48.000 Y40.000'") != std::string::npos;
    }
    EXPECT_TRUE(dragged) << "no tool-down-off-path on the rapid to the circle";

    const PlotRun improved = plot_example(true);
    for (const Finding& f : improved.findings) ADD_FAILURE() << f.describe();
    // The G-code's eight moves (two rapids, four lines and an arc, the
    // circle): all but the last one left behind, the last one at rest at its
    // end - every one judged.
    const auto& oracle = improved.run->bench().board().part_as<MotionOracle>("motion");
    EXPECT_EQ(oracle.moves_judged(), 8u);
    EXPECT_TRUE(oracle.judging());
    EXPECT_NEAR(improved.y_end_mm, 40.0, 1.0 / 160);
}

// Code 4.11 reads every coordinate into a 16-bit int of 1000 BLU/mm, relative
// (digest §9.8): X40 is 40 000 BLU, -25 536 as an int16, so X runs the other
// way. The job says G91 as a host must for a relative firmware. The
// excitation runs at 630 rpm, too fast for the motor, which stalls after
// 11 steps backwards (0.115 mm): within the path tolerance plus one step of
// each axis (0.1 + 0.017 mm) of the commanded line, but at rest before the
// move began and away from its start - a move-end-missed on line 2.
TEST(MotionOracle, TheThesisParsersSixteenBitWrapIsAFinding) {
    auto bench = test::powered_printer("printer3d_interp_thesis_parser");
    bench->run_for(0.2);
    bench->host().add_lines("G91\nG01 X40 F10\n");
    bench->run_until_idle(10.0);
    const auto findings = bench->findings();
    bool wrong_way = false;
    for (const Finding* f : of_kind(findings, MotionOracle::kMoveEndMissed)) {
        wrong_way = wrong_way || (f->detail.find("line 2 'G01 X40 F10'") != std::string::npos &&
                                  f->detail.find("came to rest 0.115 mm from this move's start, before it began") !=
                                      std::string::npos);
    }
    EXPECT_TRUE(wrong_way) << "no move-end-missed on G01 X40";
    // The carriage went below its power-up place (the firmware's 0), away
    // from the commanded +40 mm.
    EXPECT_LT(bench->axis("x").position_mm(), 3.5);

    // The fixed parser takes the same two lines: X ends 40 mm on, no finding.
    auto fixed = test::powered_printer();
    fixed->run_for(0.2);
    fixed->host().add_lines("G91\nG1 X40 F600\nM400\n");  // M400: the job ends when the move does
    fixed->run_until_idle(20.0);
    EXPECT_NEAR(fixed->axis("x").position_mm(), 3.5 + 40.0, 0.01);
    for (const Finding& f : fixed->findings()) ADD_FAILURE() << f.describe();
}

// Lines go to the oracle as they are sent; one the firmware refuses is taken
// back. The improved interpolator answers "Error:target out of range" (and
// its "ok") to X99999 (more than its 32-bit BLU range allows), already after
// the host queued the next line: the line after it is read again from the
// position before it, X10, and the job ends at X20 with nothing found.
TEST(MotionOracle, ARefusedLineIsTakenBack) {
    auto bench = test::powered_printer();
    bench->run_for(0.2);
    bench->host().add_lines("G1 X10 F300\nG1 X99999 F300\nG1 X20 F300\nM400\n");
    bench->run_until_idle(20.0);
    EXPECT_EQ(bench->host().errors(), 1u);
    EXPECT_NEAR(bench->axis("x").position_mm(), 3.5 + 20.0, 0.01);
    for (const Finding& f : bench->findings()) {
        if (f.kind != UartHost::kHostProtocol) ADD_FAILURE() << f.describe();
    }
    const auto& oracle = bench->board().part_as<MotionOracle>("motion");
    EXPECT_TRUE(oracle.judging());
    EXPECT_EQ(oracle.moves_judged(), 2u);  // X10 left behind, X20 where it rests
}

// A machine that never makes an accepted move: once the job's every line is
// answered and the machine rests at the end, the first move it never began
// is a finding, unless a dwell (G4) stands before it - the firmware may
// still be waiting it out when the run ends. The oracle is told by hand:
// an X carriage that nothing drives (its driver's STEP is not wired).
std::vector<Finding> unmade(bool dwell_first) {
    Bench bench(parse_board_text(R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 16}
  x: {type: linear_axis, steps_per_mm: 80, travel: 200mm, start_position: 10mm}
  motion: {type: motion_oracle}
nets:
  x_motion: [x_driver.steps, x.drive]
  x_carriage: [x.carriage, motion.x]
)",
                                 "unmade.yaml"),
                {{"uno", test::firmware("sleep_idle")}});
    auto& oracle = bench.board().part_as<MotionOracle>("motion");
    bench.run_for(0.01);
    if (dwell_first) oracle.dwell();
    CommandedMove move;
    move.kind = CommandedMove::Kind::Feed;
    move.from_mm = {0.0, 0.0, 0.0};
    move.to_mm = {5.0, 0.0, 0.0};
    move.line = "line 1 'G1 X5'";
    oracle.commanded(move);
    oracle.job_answered_by([] { return true; });
    bench.run_for(0.5);
    std::vector<Finding> out;
    for (const Finding& f : bench.findings()) {
        if (f.kind == MotionOracle::kMoveEndMissed) out.push_back(f);
    }
    return out;
}

TEST(MotionOracle, AMoveNeverMadeIsAFindingUnlessADwellStandsBeforeIt) {
    const auto found = unmade(false);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_NE(found[0].detail.find("line 1 'G1 X5': every line was answered, and the run ended with the machine at rest "
                                   "at X0.000 before this move to X5.000 began"),
              std::string::npos)
        << found[0].detail;
    EXPECT_TRUE(unmade(true).empty());
}

}  // namespace
}  // namespace avrbench
