// Motors driven other ways than the seed 003 shield: by a step/dir driver
// (its microstep current vector, ideal chopper), and seed 001's unipolar
// drive board (low-side switches, flyback diodes, sense resistors read by
// the firmware's ADC chopper). Also the board-file errors of the motor parts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "boards/Board.hpp"
#include "parts/HybridStepper.hpp"
#include "parts/StepDirDriver.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

// Seed 002's X axis: DRV8825 at 1/16 (jumpers), 42BYGHW208 at 0.4 A and 12 V,
// and the gantry's load inertia J_T - J_M = 1.42e-4 - 1.5e-6 kg*m^2 (seed 002
// §2.1.4, eq. 2.6).
const char* const kStepDirBoard = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  x_driver: {type: step_dir_driver, preset: drv8825, microsteps: 16, current: 0.4A, motor_supply: 12V}
  motor: {type: hybrid_stepper, preset: 42byghw208, load_inertia: 1.405e-4kg*m^2}
nets:
  x_driver_windings: [x_driver.windings, motor.windings]
  x_step: [uno.PD2, x_driver.step]
  x_dir: [uno.PD5, x_driver.dir]
  enable: [uno.PB0, x_driver.enable]
)";

struct StepDirRun {
    Board board;
    HybridStepper& motor;
    explicit StepDirRun(const std::string& firmware)
        : board(parse_board_text(kStepDirBoard, "stepdir-motor.yaml"), {{"uno", test::firmware(firmware)}}),
          motor(board.part_as<HybridStepper>("motor")) {
        board.run_until_seconds(1.5);
        EXPECT_EQ(board.mcu().read_ram_u8("done"), 1);
        EXPECT_EQ(board.mcu().read_ram_u16("step_count"), 6400);  // two revolutions at 1/16
    }
};

TEST(MotorDriverDriven, RampedMoveKeepsEveryStep) {
    // AVR446 ramp at 100 rad/s^2: the load needs J * alpha = 0.014 N*m.
    StepDirRun run("stepdir_ramp");
    EXPECT_EQ(run.motor.lost_steps(), 0);
    EXPECT_EQ(run.motor.stalls(), 0u);
    // Two revolutions from the driver's home microstep (45 deg electrical =
    // 0.9 deg from the rotor's A+ detent).
    EXPECT_NEAR(run.motor.angle_deg(), 720.9, 0.2);
    EXPECT_NEAR(run.motor.following_error_deg(), 0, 0.2);
    EXPECT_EQ(run.board.part_as<StepDirDriver>("x_driver").position_256(), 6400 * 16);
}

TEST(MotorDriverDriven, MoveWithoutRampLosesSteps) {
    // 200 rpm from the first step: the gantry would need its full speed
    // within one microstep; the rotor cannot follow.
    StepDirRun run("stepdir_no_ramp");
    EXPECT_GE(run.motor.lost_steps(), 200);  // most of the 400 full steps
    EXPECT_EQ(run.motor.lost_steps() % 4, 0);
    EXPECT_GE(run.motor.stalls(), 1u);
    // The driver counted every pulse: only the physics lost them.
    EXPECT_EQ(run.board.part_as<StepDirDriver>("x_driver").position_256(), 6400 * 16);
}

TEST(MotorUnipolar, ChopperHoldsTheCurrentAtTheSenseLimit) {
    // Seed 001 board: 12 V centre taps, 6.8 ohm half-windings, 2.2 ohm sense
    // resistors. Unchopped a winding would draw (12 - 0.3) / (6.8 + 2.2) =
    // 1.30 A; the firmware switches a pair off while its ADCH > 100, i.e.
    // above 101 * 5 V / 256 / 2.2 ohm = 0.897 A.
    Board board(load_board_file(test::source_path("bench/boards/unipolar-drive-board.yaml")),
                {{"drive", test::firmware("unipolar_chopper")}});
    auto& motor = board.part_as<HybridStepper>("motor");
    Mcu& drive = board.mcu("drive");
    double peak = 0, sum = 0;
    int samples = 0;
    for (int i = 1; i <= 2500; ++i) {
        board.run_until_seconds(i * 1e-3);
        motor.sync();
        if (i < 100) continue;  // after the first steps
        const double a = std::fabs(motor.phase_current(0)), b = std::fabs(motor.phase_current(1));
        peak = std::max({peak, a, b});
        sum += a + b;
        samples += 2;
    }
    EXPECT_EQ(drive.read_ram_u16("steps"), 400);
    EXPECT_GT(drive.read_ram_u16("chops"), 100);
    EXPECT_GT(drive.read_ram_u8("max_adch"), 100);  // the ADC saw the sense voltage above the limit
    EXPECT_LT(peak, 0.897 * 1.15);                 // never near the unchopped 1.30 A
    EXPECT_GT(sum / samples, 0.6);                 // but chopping around the limit, not starving
    EXPECT_EQ(motor.lost_steps(), 0);
    // 400 full steps (two-phase, AB first = 0.9 deg) at 60 rpm.
    EXPECT_NEAR(motor.angle_deg(), 0.9 + 400 * 1.8, 0.5);
}

std::string motor_board_error(const std::string& motor_line) {
    const std::string text = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  ic: {type: l293d}
  x_driver: {type: step_dir_driver, preset: a4988}
)" + motor_line + "\n";
    try {
        Board board(parse_board_text(text, "motor.yaml"), {{"uno", test::firmware("sleep_idle")}});
    } catch (const BadInput& e) {
        return e.what();
    }
    return "";
}

TEST(MotorBoard, OneNetGivesTheWindingsOneSource) {
    const auto e = motor_board_error("  m: {type: hybrid_stepper}\nnets:\n  w: [ic.windings, x_driver.windings, m.windings]");
    EXPECT_EQ(e, "motor.yaml:9: net 'w' has two windings providers: ic.windings and x_driver.windings");
}

TEST(MotorBoard, UnconnectedWindingsNameThePort) {
    EXPECT_EQ(motor_board_error("  m: {type: hybrid_stepper}"),
              "motor.yaml:7: part 'm' (hybrid_stepper): port 'windings' is not connected: join it to an l293d's or a "
              "step_dir_driver's windings in nets:");
}

TEST(MotorBoard, BadPhaseOutputsNameThePart) {
    const auto e = motor_board_error("  m: {type: hybrid_stepper, phase_a: \"1-2\"}");
    EXPECT_NE(e.find("part 'm'"), std::string::npos) << e;
    EXPECT_NE(e.find("phase_a"), std::string::npos) << e;
}

TEST(MotorBoard, PhaseOutputsMustBeOutputsOfTheBridge) {
    // The L293D has outputs 1Y..4Y (TI SLRS008C).
    EXPECT_EQ(motor_board_error("  m: {type: hybrid_stepper, phase_b: \"3,5\"}\nnets:\n  w: [ic.windings, m.windings]"),
              "motor.yaml:7: part 'm': L293D outputs are 1..4, not 5");
}

TEST(MotorBoard, UnitsAreChecked) {
    const auto e = motor_board_error("  m: {type: hybrid_stepper, rotor_inertia: 35g}");
    EXPECT_NE(e.find("rotor_inertia"), std::string::npos) << e;
}

}  // namespace
}  // namespace avrbench
