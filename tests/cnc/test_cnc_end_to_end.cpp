// Seed 002 end to end: a DXF drawing (a line, an arc and a circle) through
// the CAM (bench/cam) to G-code, to the firmware's binary records, streamed
// stop-and-wait to firmware/cnc2axis on its board; the pen's strokes must
// retrace the drawing. Each test runs under ctest's 300 s wall-clock limit.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "boards/Board.hpp"
#include "cam/Chain.hpp"
#include "cam/DxfReader.hpp"
#include "cam/Records.hpp"
#include "core/Errors.hpp"
#include "periph/usart/Uart.hpp"
#include "parts/Axis.hpp"
#include "parts/PenLift.hpp"
#include "stimulus/RecordHost.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

// Distance from p to the drawing's nearest segment (lines; arcs as their circle's sector).
double distance_to(const Drawing& d, const Point2& p) {
    double best = 1e9;
    for (const auto& s : d.segments) {
        if (s.kind == Segment::Kind::Line) {
            const double vx = s.end.x - s.start.x, vy = s.end.y - s.start.y;
            const double len2 = vx * vx + vy * vy;
            const double t = len2 > 0 ? std::clamp(((p.x - s.start.x) * vx + (p.y - s.start.y) * vy) / len2, 0.0, 1.0) : 0.0;
            best = std::min(best, distance(p, {s.start.x + t * vx, s.start.y + t * vy}));
        } else {
            const double r = distance(s.start, s.centre);
            best = std::min(best, std::abs(distance(p, s.centre) - r));  // the arcs here span their own sector
        }
    }
    return best;
}

struct Job {
    Drawing drawing;
    GcodeProgram gcode;
    RecordProgram records;
};

Job prepare(const std::string& dxf, bool improved, double feed_mm_per_min) {
    Job j;
    j.drawing = read_dxf(dxf).drawing;
    align_segments(j.drawing, 0.01);
    j.gcode = emit_gcode(j.drawing, 0.01, feed_mm_per_min);
    RecordOptions o;
    o.improved = improved;
    j.records = records_from_gcode(j.gcode.text, o, dxf);
    return j;
}

// The improved firmware on the plotter board, homed, with `job`'s records
// streamed until they are all acknowledged, the host fails, or `limit_s`.
struct Plot {
    Board board{load_board_file(test::source_path("bench/boards/cnc2axis-seed002.yaml")),
                {{"uno", test::firmware("cnc2axis_improved")}}};
    Mcu& uno = board.mcu("uno");
    RecordHost host;
    Plot(const Job& job, double limit_s) : host(uno, uno.uart(0), job.records.messages, {}, job.records.busy_seconds) {
        double t = 0;
        while (uno.read_ram_u8("homed") == 0 && t < 5) board.run_until_seconds(t += 0.1);
        host.start();
        while (!host.finished() && !host.failed() && t < limit_s) board.run_until_seconds(t += 0.5);
    }
};

TEST(CncEndToEnd, TheImprovedBuildRetracesALineAnArcAndACircle) {
    const Job job = prepare(test::source_path("tests/fixtures/dxf/line_arc_circle.dxf"), true, 120);
    // 2 rapids, a line; the 90-degree arc of R 20 in chords short enough for
    // 8-bit counts (255 microsteps = 1.594 mm: 2 asin(1.594 / 40) = 4.57 deg,
    // 20 chords), the circle of R 15 in 5-degree chords (72), M30.
    EXPECT_EQ(job.records.moves, 3u);
    EXPECT_EQ(job.records.arcs, 2u);
    EXPECT_EQ(job.records.chords, 20u + 72u);
    // 145 mm of drawing at 2 mm/s and the rapids: well under 120 s.
    Plot plot(job, 120);
    Board& board = plot.board;
    Mcu& uno = plot.uno;
    const RecordHost& host = plot.host;
    ASSERT_TRUE(host.finished()) << host.failure() << " (" << host.acknowledged() << " of " << host.messages() << ")";
    board.run_for_seconds(0.5);
    EXPECT_TRUE(uno.halted());  // M30
    EXPECT_TRUE(board.findings().empty());

    const auto& strokes = board.part_as<PenLift>("pen").strokes();
    ASSERT_EQ(strokes.size(), job.gcode.pen_cycles);  // one pen-down spell per path: 2
    // Where each path starts and ends: to the microstep (1/160 mm), both axes counted.
    const double microstep = 1.0 / 160.0;
    EXPECT_NEAR(strokes[0].front().x_mm, 30.0, 2 * microstep);
    EXPECT_NEAR(strokes[0].front().y_mm, 70.0, 2 * microstep);
    EXPECT_NEAR(strokes[0].back().x_mm, 70.0, 2 * microstep);
    EXPECT_NEAR(strokes[0].back().y_mm, 50.0, 2 * microstep);
    EXPECT_NEAR(strokes[1].front().x_mm, 115.0, 2 * microstep);
    EXPECT_NEAR(strokes[1].back().x_mm, 115.0, 2 * microstep);
    // Every pen point near the drawing. The bound: within a move both axes
    // run at rates quantised by OCR at N = 1024 (at 2 mm/s OCR + 1 >= 24, a
    // rate error <= 0.5 / 24 = 2.1 %), so an axis may lead the other by up to
    // 2.1 % of the move (0.42 mm on the 20 mm line, less on the chords of
    // at most 1.7 mm), plus the chord error R (1 - cos 2.5 deg) < 0.02 mm.
    double worst = 0;
    for (const auto& stroke : strokes) {
        for (const auto& p : stroke) worst = std::max(worst, distance_to(job.drawing, {p.x_mm, p.y_mm}));
    }
    EXPECT_LT(worst, 0.45);
    // The circle alone (R 15 mm, 72 chords of 5 deg, at most 1.31 mm each):
    // within its chord error R (1 - cos 2.5 deg) = 0.014 mm, plus an axis
    // leading the other by 2.1 % of a chord (0.028 mm), plus 2 microsteps of
    // rounding (0.0125 mm): 0.055 mm.
    double worst_on_circle = 0;
    for (const auto& p : strokes[1]) {
        worst_on_circle = std::max(worst_on_circle, std::abs(distance({p.x_mm, p.y_mm}, {100.0, 50.0}) - 15.0));
    }
    EXPECT_LT(worst_on_circle, 0.055);
}

TEST(CncEndToEnd, LongCountedMovesEndWhereTheyShould) {
    // The demo drawing (examples/drawings/plotter_demo.dxf: a 40 mm square
    // with one rounded corner, then a circle of R 8 mm about (40, 40)) at
    // 2 mm/s: its 30 and 40 mm vertical lines count 4800 and 6400 Y steps in
    // the Timer2 interrupt while the main loop waits for the count to reach
    // 0. A count read byte by byte with interrupts on can look like 0 after a
    // borrow (0x1300 -> 0x12FF read as 0x1200 ... or 0x0000) and end the move
    // early; the firmware reads it whole. The pen must end at the circle's
    // start, (48, 40), with every step counted.
    const Job job = prepare(test::source_path("examples/drawings/plotter_demo.dxf"), true, 120);
    Plot plot(job, 200);
    Board& board = plot.board;
    const RecordHost& host = plot.host;
    ASSERT_TRUE(host.finished()) << host.failure();
    EXPECT_NEAR(board.part_as<Axis>("x").position_mm(), 48.0, 1.5 / 160.0);
    EXPECT_NEAR(board.part_as<Axis>("y").position_mm(), 40.0, 1.5 / 160.0);
    EXPECT_EQ(board.part_as<PenLift>("pen").strokes().size(), 2u);  // the square, the circle
    EXPECT_TRUE(board.findings().empty());
}

TEST(CncEndToEnd, AFirmwareThatNeverAnswersIsAFailureNotAHang) {
    // The records of the faithful build sent to the improved firmware: the
    // G01 record is 3 bytes short, so the firmware waits for bytes that never
    // come and sends no ACK.
    const Job job = prepare(test::source_path("tests/fixtures/dxf/three_lines.dxf"), false, 600);
    Plot plot(job, 30);
    const RecordHost& host = plot.host;
    ASSERT_TRUE(host.failed());
    EXPECT_NE(host.failure().find("no ACK for message"), std::string::npos) << host.failure();
}

TEST(CncEndToEnd, GcodeTheConverterCannotUseIsALineError) {
    RecordOptions o;
    try {
        records_from_gcode("G21 G90\nG01 X10 Y-5 F600\n", o, "job.nc");
        FAIL() << "a negative target was accepted";
    } catch (const BadInput& e) {
        EXPECT_EQ(std::string(e.what()), "job.nc:2: the target lies outside the machine (negative or beyond 10 m)");
    }
    EXPECT_THROW(records_from_gcode("G05 X1\n", o, "job.nc"), BadInput);
    EXPECT_THROW(records_from_gcode("G01 Xabc\n", o, "job.nc"), BadInput);
}

TEST(CncEndToEnd, OneCommandPlotsADxfOnTheBoard) {
    const auto dir = test::scratch_dir("cnc-plot");
    const std::string cmd = std::string(::avrbench::test::cli()) + " run -q " + test::firmware("cnc2axis_improved") +
                            " --board " + test::source_path("bench/boards/cnc2axis-seed002.yaml") + " --dxf " +
                            test::source_path("tests/fixtures/dxf/line_arc_circle.dxf") +
                            " --records improved --vcd " + (dir / "plot.vcd").string() + " --nc " + (dir / "plot.nc").string();
    const auto r = test::run_command(cmd, dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("98 of 98 records acknowledged (improved)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("pen        pen: up, 2 strokes"), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(dir / "plot.vcd"));
    EXPECT_TRUE(std::filesystem::exists(dir / "plot.nc"));
    // Without a board there is no serial port to stream to.
    const auto bad = test::run_command(std::string(::avrbench::test::cli()) + " run " + test::firmware("cnc2axis") + " --dxf x.dxf", dir);
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_EQ(bad.err, "avrbench: error: --dxf needs --board (the board file names the serial port)\n");
}

}  // namespace
}  // namespace avrbench
