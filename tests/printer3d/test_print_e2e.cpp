// Seed 001 end to end: the demo part (examples/printer3d/seed001_part.gcode)
// printed by the five MCUs of bench/boards/printer3d-seed001.yaml. The
// expected positions and extruded length are worked out from the G-code and
// the firmware's documented constants (100 BLU/mm, SP = 1/8 E step per
// tick carried across moves, 40-step retract and prime per layer).
#include <gtest/gtest.h>

#include <cmath>

#include "parts/Axis.hpp"
#include "printer3d/PrinterBench.hpp"

namespace avrbench {
namespace {


TEST(Printer3dEndToEnd, TheDemoPartEndsWhereItsGcodeSays) {
    auto bench = test::printer_bench();
    bench->host().load_file(test::source_path("examples/printer3d/seed001_part.gcode"));
    ASSERT_EQ(bench->run_until_idle(60.0), IdleResult::Idle) << bench->host().received_text();
    EXPECT_EQ(bench->host().errors(), 0u);
    // Depositing ticks per layer (one tick per BLU of path): 600 + 400 +
    // round(200 * pi / 2) = 314 + 400 + 600 = 2314; two layers 4628; E steps
    // floor(4628 / 8) = 578, primes and retracts cancelling.
    const int per_layer = 600 + 400 + static_cast<int>(std::lround(200 * M_PI / 2)) + 400 + 600;
    EXPECT_EQ(test::drive_position(*bench, "drive_e"), 2 * per_layer / 8);
    // Parked at X0 Y0 Z2 from the homed corner; homing started 3.5 / 2.5 /
    // 1.5 mm from the stops with the switches at 0.5 mm, and stops on the
    // step that trips the switch (the carriage follows the rotor's lag: a
    // step or two late).
    EXPECT_NEAR(test::drive_position(*bench, "drive_x"), -300, 2);
    EXPECT_NEAR(test::drive_position(*bench, "drive_y"), -200, 2);
    EXPECT_NEAR(test::drive_position(*bench, "drive_z"), -100 + 200, 2);
    EXPECT_NEAR(bench->axis("x").position_mm(), 0.5, 0.02);
    EXPECT_NEAR(bench->axis("y").position_mm(), 0.5, 0.02);
    EXPECT_NEAR(bench->axis("z").position_mm(), 2.5, 0.02);
    EXPECT_NE(bench->host().received_text().find("X:0.000 Y:0.000 Z:2.000"), std::string::npos);
    for (const Finding& f : bench->findings()) ADD_FAILURE() << f.source << ": " << f.detail;
}

}  // namespace
}  // namespace avrbench
