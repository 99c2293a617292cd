// The quadrature encoder on the X motor of the UNO + CNC shield board, the
// shaft turned by grbl_stepper's moves (firmware/boards/grbl_stepper/README.md:
// `X2500` steps, 80 steps/mm at 6000 mm/min by default = 8000 steps/s, one
// STEP every 125 us). The board's x_driver runs at 1/16 microstepping and
// counts DIR low as forward (bench/boards/arduino-uno-cnc-shield-v3.yaml).
#include <gtest/gtest.h>

#include <fstream>

#include "parts/QuadratureEncoder.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"
#include "support/RunCommand.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

// The shield board with an encoder of `lines` lines on the X shaft, A and B
// on PC3/PC4 (A3/A4: free in grbl_stepper's pin map).
std::string encoder_board(const std::string& name, int lines) {
    const auto path = test::scratch_dir(name) / "encoder.yaml";
    std::ofstream(path) << "board: encoder-on-x\n"
                        << "extends: " << test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml") << "\n"
                        << "parts:\n"
                        << "  x_encoder: {type: quadrature_encoder, lines_per_rev: " << lines << "}\n"
                        << "nets:\n"
                        << "  x_motion: [x_driver.steps, x.drive, x_encoder.shaft]\n"
                        << "  encoder_a: [uno.PC3, x_encoder.a]\n"
                        << "  encoder_b: [uno.PC4, x_encoder.b]\n";
    return path.string();
}

struct EncoderRun {
    Bench bench;
    test::PinLog a{bench.mcu(), "PC3"}, b{bench.mcu(), "PC4"}, step{bench.mcu(), "PD2"};
    explicit EncoderRun(int lines) : bench(encoder_board("encoder" + std::to_string(lines), lines), test::firmware("grbl_stepper")) {
        // grbl_stepper answers ok like grbl but greets with its own banner: a generic host.
        UartHostOptions host = default_host_options(bench.serial_port(""));
        host.family = FirmwareFamily::Generic;
        bench.host("", host).add_lines("X2500\n");
        bench.run_until_idle(10.0);
        EXPECT_TRUE(bench.host().done()) << bench.host().tail(10);
    }
    QuadratureEncoder& encoder() { return bench.board().part_as<QuadratureEncoder>("x_encoder"); }
};

TEST(QuadratureEncoder, CountsTheShaftsTurnOnItsPins) {
    EncoderRun run(100);
    // 2500 steps at 1/16 = 156.25 full steps of 200 per turn = 0.78125 turn;
    // 100 lines x 4 counts = 400 counts per turn: floor(312.5) = 312 counts.
    EXPECT_EQ(run.encoder().count(), 312);
    EXPECT_EQ(run.encoder().edges(), 312u);
    // Gray code: A rises on counts 4k+1, B on 4k+2: 78 rises each in 312
    // counts, and both low again at count 312 (a multiple of 4).
    EXPECT_EQ(run.a.rises().size(), 78u);
    EXPECT_EQ(run.b.rises().size(), 78u);
    EXPECT_FALSE(run.bench.mcu().pin("PC3").level());
    EXPECT_FALSE(run.bench.mcu().pin("PC4").level());
    // A leads B going forward: the first A rise comes before the first B rise.
    ASSERT_FALSE(run.a.rises().empty());
    ASSERT_FALSE(run.b.rises().empty());
    EXPECT_LT(run.a.rises().front(), run.b.rises().front());
    // A count every 8 steps (3200 steps / 400 counts) of 125 us: 1 ms apart,
    // far above the 10 us the decoder needs: no finding.
    EXPECT_TRUE(run.encoder().findings().empty());
}

TEST(QuadratureEncoder, EdgesFasterThanTheDecoderAreAFinding) {
    EncoderRun run(2000);
    // 8000 counts per turn / 3200 steps = 2.5 counts per step: two or three
    // edges in the instant of one STEP edge, 0 us apart.
    EXPECT_EQ(run.encoder().count(), 6250);  // 2500 x 2.5
    const auto& findings = run.encoder().findings();
    ASSERT_EQ(findings.size(), 1u) << "one finding for the first burst; the summary counts the rest";
    EXPECT_EQ(findings[0].kind, QuadratureEncoder::kEdgesTooFast);
    // The first STEP rise turns the shaft 1/16 step: 2.5 counts, the second
    // edge at the same cycle.
    ASSERT_FALSE(run.step.rises().empty());
    EXPECT_EQ(findings[0].cycle, run.step.rises().front());
    EXPECT_NE(run.encoder().summary().find("edges too close"), std::string::npos) << run.encoder().summary();
}

}  // namespace
}  // namespace avrbench
