// Seed 002's CAM side (bench/cam): DXF entities read with dxflib, chained by
// the thesis' alignment algorithm with a distance tolerance, emitted as
// G-code with the thesis' rule (a G00 only where the pen must move without
// drawing). Fixtures: tests/fixtures/dxf/ (written by hand, geometry in the
// comments below).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "cam/Chain.hpp"
#include "cam/DxfReader.hpp"
#include "core/Errors.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

std::string fixture(const std::string& name) { return test::source_path("tests/fixtures/dxf/" + name); }

TEST(Cam, DxfLinesArcsAndCirclesAreRead) {
    const auto r = read_dxf(fixture("line_arc_circle.dxf"));
    ASSERT_EQ(r.drawing.segments.size(), 3u);
    const Segment& line = r.drawing.segments[0];
    EXPECT_EQ(line.kind, Segment::Kind::Line);
    EXPECT_DOUBLE_EQ(line.start.x, 30.0);
    EXPECT_DOUBLE_EQ(line.end.x, 50.0);
    // ARC centre (50, 50), radius 20, 0..90 deg, counter-clockwise: (70, 50) -> (50, 70).
    const Segment& arc = r.drawing.segments[1];
    EXPECT_EQ(arc.kind, Segment::Kind::ArcCcw);
    EXPECT_NEAR(arc.start.x, 70.0, 1e-9);
    EXPECT_NEAR(arc.start.y, 50.0, 1e-9);
    EXPECT_NEAR(arc.end.x, 50.0, 1e-9);
    EXPECT_NEAR(arc.end.y, 70.0, 1e-9);
    // CIRCLE centre (100, 50), radius 15: a clockwise arc from and to (115, 50).
    const Segment& circle = r.drawing.segments[2];
    EXPECT_EQ(circle.kind, Segment::Kind::ArcCw);
    EXPECT_NEAR(circle.start.x, 115.0, 1e-9);
    EXPECT_NEAR(distance(circle.start, circle.end), 0.0, 1e-12);
}

TEST(Cam, AligningThreeLinesSavesTwoRapids) {
    // Seed 002's Draft 1.1: three lines of one path, saved out of order and
    // partly backwards: 6 commands (a G00 before each line) become 4 (one G00,
    // three G01), one pen-down spell.
    auto r = read_dxf(fixture("three_lines.dxf"));
    const GcodeProgram before = emit_gcode(r.drawing, 0.01, 600);
    EXPECT_EQ(before.commands, 6u);
    EXPECT_EQ(before.pen_cycles, 3u);
    align_segments(r.drawing, 0.01);
    const GcodeProgram after = emit_gcode(r.drawing, 0.01, 600);
    EXPECT_EQ(after.commands, 4u);
    EXPECT_EQ(after.rapids, 1u);
    EXPECT_EQ(after.pen_cycles, 1u);
    // Each segment starts where the one before ends.
    for (std::size_t i = 1; i < r.drawing.segments.size(); ++i) {
        EXPECT_LT(distance(r.drawing.segments[i - 1].end, r.drawing.segments[i].start), 1e-9);
    }
}

TEST(Cam, AClosedPathRunsTheThesisLoopToItsCap) {
    // App. A1's case 3 ("k ends where j starts: k goes first") holds for
    // some pair of every closed path whatever its order (its first segment
    // starts where a later one ends), so the loop's flag is set on every pass
    // and it stops only at the thesis' cap of 100 revisions. The example
    // drawing (a closed outline of four lines and an arc, and a circle) is
    // two paths: two rapids whatever the passes did.
    auto r = read_dxf(test::source_path("examples/drawings/plotter_demo.dxf"));
    const ChainStats stats = align_segments(r.drawing, 0.01);
    EXPECT_EQ(stats.revisions, 100u);
    const GcodeProgram p = emit_gcode(r.drawing, 0.01, 120);
    EXPECT_EQ(p.rapids, 2u);
    EXPECT_EQ(p.pen_cycles, 2u);
}

TEST(Cam, ToleranceJoinsEndpointsThatExactEqualityWouldNot) {
    // One endpoint 0.004 mm off: with the thesis' exact comparison the path
    // breaks there (an extra pen lift); within 0.01 mm it is one path.
    auto exact = read_dxf(fixture("three_lines_rounded.dxf"));
    align_segments(exact.drawing, 0.0);
    EXPECT_GT(emit_gcode(exact.drawing, 0.0, 600).rapids, 1u);
    auto tolerant = read_dxf(fixture("three_lines_rounded.dxf"));
    align_segments(tolerant.drawing, 0.01);
    EXPECT_EQ(emit_gcode(tolerant.drawing, 0.01, 600).rapids, 1u);
}

TEST(Cam, ArcsKeepTheirCentreWhenReversed) {
    auto r = read_dxf(fixture("line_arc_circle.dxf"));
    align_segments(r.drawing, 0.01);
    const GcodeProgram p = emit_gcode(r.drawing, 0.01, 600);
    // The line ends at (50, 70), where the arc ends: the arc is drawn
    // clockwise from (50, 70) to (70, 50), its centre (50, 50) at I 0, J -20.
    EXPECT_NE(p.text.find("G01 X50.000 Y70.000 F600\nG02 X70.000 Y50.000 I0.000 J-20.000 F600\n"), std::string::npos)
        << p.text;
    EXPECT_EQ(p.text.substr(p.text.size() - 4), "M30\n");
}

TEST(Cam, BadFilesAreOneLineErrors) {
    EXPECT_THROW(read_dxf(fixture("missing.dxf")), BadInput);
    try {
        read_dxf(fixture("text_only.dxf"));
        FAIL() << "a drawing without lines was accepted";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("no LINE, ARC or CIRCLE"), std::string::npos) << e.what();
    }
}

TEST(Cam, CliWritesTheProgramAndSaysWhatItSaved) {
    const auto dir = test::scratch_dir("cam-cli");
    const auto out = (dir / "three.nc").string();
    const auto r = test::run_command(std::string(::avrbench::test::cli()) + " cam " + fixture("three_lines.dxf") + " -o " + out, dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("commands   6 -> 4 (rapids 3 -> 1)"), std::string::npos) << r.out;
    // The default feed is run --dxf's, 120 mm/min (one default for both, issue 40).
    std::ifstream written(out);
    const std::string program((std::istreambuf_iterator<char>(written)), std::istreambuf_iterator<char>());
    EXPECT_NE(program.find(" F120\n"), std::string::npos) << program;
    EXPECT_EQ(program.find("F600"), std::string::npos) << program;
    const auto missing = test::run_command(std::string(::avrbench::test::cli()) + " cam " + (dir / "nope.dxf").string(), dir);
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_EQ(missing.err, "avrbench: error: DXF drawing: " + (dir / "nope.dxf").string() + ": no such file\n");
}

}  // namespace
}  // namespace avrbench
