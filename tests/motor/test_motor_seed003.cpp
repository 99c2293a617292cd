// Validation of the coil-driven motor against seed 003 (Fioretos 2015): an
// Arduino UNO + Adafruit Motor Shield v1 (74HC595 + L293D at 12 V) driving
// the SM-42BYG011-25 without load, with our reproductions of the thesis's
// experiments (firmware/motor/). Bounds are +-15 % of the thesis's
// measurements (seed 003 §4.1 / digest §1.7): pull-out 200 rpm two-phase-on,
// 150 rpm one-phase-on; start/stop 170 rpm two-phase-on. docs/MOTOR.md
// records the exact figures.
//
// Long tests: the two sweeps simulate ~45 s each (about 0.7 s of wall time
// on the CI machine); MotorSeed003.PullOutDoesNotDriftWithTheIntegrationStep
// runs the two-phase sweep twice, once at half the step (~2.5 s).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "boards/Board.hpp"
#include "parts/HybridStepper.hpp"
#include "parts/ShiftRegister595.hpp"
#include "support/Paths.hpp"
#include "trace/GtkwWriter.hpp"
#include "trace/Recorder.hpp"
#include "trace/VcdReader.hpp"
#include "trace/VcdWriter.hpp"

namespace avrbench {
namespace {

const char* const kBoard = "bench/boards/arduino-uno-motor-shield-v1.yaml";

BoardSpec shield_spec(const std::string& max_step = "") {
    BoardSpec spec = load_board_file(test::source_path(kBoard));
    if (!max_step.empty()) {
        for (auto& part : spec.parts) {
            if (part.name == "motor") part.params.push_back({"max_step", max_step, "test"});
        }
    }
    return spec;
}

struct ShieldRun {
    Board board;
    HybridStepper& motor;
    Mcu& uno;
    explicit ShieldRun(const std::string& firmware, const std::string& max_step = "")
        : board(shield_spec(max_step), {{"uno", test::firmware(firmware)}}),
          motor(board.part_as<HybridStepper>("motor")),
          uno(board.mcu("uno")) {}
};

// Runs a sweep firmware until the motor first loses synchronism; returns the
// firmware's speed (rpm of the revolution in progress) at that moment.
std::optional<unsigned> first_stall_rpm(ShieldRun& run, unsigned give_up_rpm) {
    std::optional<unsigned> stall;
    run.motor.on_stall([&](const HybridStepper::StallEvent&) {
        if (!stall) stall = run.uno.read_ram_u16("rpm");
        run.uno.request_stop();
    });
    double t = 0;
    while (!stall && run.uno.read_ram_u16("rpm") <= give_up_rpm && t < 120) {
        t += 1.0;
        run.board.run_until_seconds(t);
    }
    return stall;
}

TEST(MotorSeed003, TwoPhaseOnSweepKeepsSyncTo170RpmAndLosesItBy230) {
    // sketch_06: +1 rpm per revolution, DOUBLE; thesis: pull-out ~200 rpm.
    ShieldRun run("motor_sweep_double");
    const auto stall = first_stall_rpm(run, 240);
    ASSERT_TRUE(stall.has_value()) << "no loss of synchronism up to 240 rpm";
    EXPECT_GE(*stall, 170u);  // 200 rpm - 15 %
    EXPECT_LE(*stall, 230u);  // 200 rpm + 15 %
    RecordProperty("stall_rpm", static_cast<int>(*stall));
    EXPECT_EQ(run.motor.lost_steps() % 4, 0);
}

TEST(MotorSeed003, OnePhaseOnSweepLosesSyncBetween128And173Rpm) {
    // The same sweep, SINGLE; thesis: pull-out ~150 rpm.
    ShieldRun run("motor_sweep_single");
    const auto stall = first_stall_rpm(run, 200);
    ASSERT_TRUE(stall.has_value()) << "no loss of synchronism up to 200 rpm";
    EXPECT_GE(*stall, 128u);  // 150 rpm - 15 %
    EXPECT_LE(*stall, 173u);  // 150 rpm + 15 %
    RecordProperty("stall_rpm", static_cast<int>(*stall));
}

TEST(MotorSeed003, PullOutDoesNotDriftWithTheIntegrationStep) {
    // The two-phase sweep with half the default 20 us RK4 step stalls in the
    // same revolution (StepperModel.PullOutSpeedDoesNotDriftWithTheStepSize
    // covers 5 to 40 us on the bare model).
    ShieldRun coarse("motor_sweep_double");
    ShieldRun fine("motor_sweep_double", "10us");
    const auto a = first_stall_rpm(coarse, 240);
    const auto b = first_stall_rpm(fine, 240);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(*a, *b);
}

TEST(MotorSeed003, StartFromRestAt145RpmKeepsEveryStep) {
    // Start/stop rate 170 rpm two-phase-on (thesis); 145 = 170 - 15 %.
    ShieldRun run("motor_start_145");
    run.board.run_until_seconds(1.0);
    ASSERT_EQ(run.uno.read_ram_u8("done"), 1);
    EXPECT_EQ(run.uno.read_ram_u16("steps"), 200);
    EXPECT_EQ(run.motor.lost_steps(), 0);
    EXPECT_EQ(run.motor.stalls(), 0u);
    // 200 DOUBLE steps from the A+ detent: A+B+ first (0.9 deg), then 199
    // full steps of 1.8 deg = 359.1 deg; released on a two-phase position.
    EXPECT_NEAR(run.motor.angle_deg(), 359.1, 0.5);
}

TEST(MotorSeed003, StartFromRestAt196RpmLosesSteps) {
    // 196 = 170 + 15 %: the rotor cannot follow a start without a ramp.
    ShieldRun run("motor_start_196");
    run.board.run_until_seconds(1.0);
    ASSERT_EQ(run.uno.read_ram_u8("done"), 1);
    EXPECT_GT(run.motor.lost_steps(), 0);
    EXPECT_EQ(run.motor.lost_steps() % 4, 0);
    EXPECT_GE(run.motor.stalls(), 1u);
    bool flagged = false;
    for (const auto& f : run.board.findings()) flagged = flagged || f.kind == HybridStepper::kMotorStall;
    EXPECT_TRUE(flagged);
}

// One-phase-on starts (the thesis: 100 rpm). One winding gives 1/sqrt(2) of
// the two-phase torque, and a start from rest at a step rate w needs an
// acceleration ~ w^2 per step angle, so the rate scales as sqrt(torque):
// 170 rpm x 2^(-1/4) = 143 rpm is the most a one-phase start can reach from
// the calibrated two-phase 170. The thesis' 100 starts; 145 must not.
TEST(MotorSeed003, OnePhaseOnStartsAtTheThesisRateAndNotAboveTheTorqueBound) {
    ShieldRun keeps("motor_start_single_100");
    keeps.board.run_until_seconds(1.0);
    ASSERT_EQ(keeps.uno.read_ram_u8("done"), 1);
    EXPECT_EQ(keeps.uno.read_ram_u16("steps"), 200);
    EXPECT_EQ(keeps.motor.lost_steps(), 0);
    EXPECT_EQ(keeps.motor.stalls(), 0u);
    ShieldRun loses("motor_start_single_145");
    loses.board.run_until_seconds(1.0);
    ASSERT_EQ(loses.uno.read_ram_u8("done"), 1);
    EXPECT_GT(loses.motor.lost_steps(), 0);
    EXPECT_EQ(loses.motor.lost_steps() % 4, 0);
}

TEST(MotorSeed003, Avr446RampTo200RpmLosesNoSteps) {
    // Seed 003 §4.2: 100 rad/s^2 to 200 rpm, a 400-step move; the thesis's
    // table reaches 200 rpm after 70 steps and ends the move at 0.7903 s.
    ShieldRun run("motor_avr446");
    std::optional<double> done_at;
    for (int i = 1; i <= 120 && !done_at; ++i) {
        run.board.run_until_seconds(i * 0.01);
        if (run.uno.read_ram_u8("done")) done_at = run.board.now_seconds();
    }
    ASSERT_TRUE(done_at.has_value());
    EXPECT_EQ(run.uno.read_ram_u16("step_count"), 400);
    EXPECT_NEAR(*done_at, 0.7903, 0.03);
    // Full speed: min_delay = alpha f_t / omega = 0.0314159 * 2 MHz / 20.94 rad/s
    // = 3000 ticks (1.5 ms); AVR446 hands over to the deceleration with the
    // last acceleration delay, a little shorter: the thesis's table has c_70 =
    // 1492 us at 1 MHz, 2984 ticks here.
    EXPECT_GE(run.uno.read_ram_u16("min_delay_used"), 2984);
    EXPECT_LE(run.uno.read_ram_u16("min_delay_used"), 3000);
    run.board.run_until_seconds(1.2);
    EXPECT_EQ(run.motor.lost_steps(), 0);
    EXPECT_EQ(run.motor.stalls(), 0u);
    // 0.9 deg for the first (A+B+) step, 1.8 deg for each of the other 399.
    EXPECT_NEAR(run.motor.angle_deg(), 0.9 + 399 * 1.8, 0.2);
}

struct ThesisRun : ShieldRun {
    ThesisRun() : ShieldRun("thesis_fsm") {
        uno.uart(0).send("ARDS");
        for (int i = 1; i <= 40 && uno.read_ram_u8("bench_phase") != 4; ++i) board.run_until_seconds(i * 0.1);
        board.run_for_seconds(0.2);
    }
};

TEST(MotorSeed003, ThesisDelayTruncationIsFlaggedAsLostSteps) {
    ThesisRun run;
    ASSERT_EQ(run.uno.read_ram_u8("bench_phase"), 4) << run.uno.uart(0).transmitted_text();
    // setup()'s printout, as the digest computes it (§3.3, §7.6).
    const std::string out = run.uno.uart(0).transmitted_text();
    EXPECT_NE(out.find("c = 1577.89"), std::string::npos) << out;
    EXPECT_NE(out.find("n= 210"), std::string::npos) << out;
    EXPECT_NE(out.find("n2= -210"), std::string::npos) << out;
    EXPECT_NE(out.find("DONE!"), std::string::npos) << out;
    EXPECT_EQ(run.uno.read_ram_u16("bench_steps"), 600);  // 210 + 180 + 210
    // The truncated delays drive the motor above its pull-out speed.
    std::vector<Finding> stalls;
    for (const auto& f : run.board.findings()) {
        if (f.kind == HybridStepper::kMotorStall) stalls.push_back(f);
    }
    ASSERT_FALSE(stalls.empty());
    EXPECT_EQ(stalls.front().source, "motor");
    EXPECT_GT(run.motor.lost_steps(), 0);
    EXPECT_EQ(run.motor.lost_steps() % 4, 0);
    // The first stall comes during the acceleration's delay(1) steps (~1.1 ms
    // apart: well above 200 rpm), not in the correct part of the ramp.
    EXPECT_NE(stalls.front().detail.find("excitation at"), std::string::npos);
    // Released on the last two-phase position: the rotor is off by whole
    // pole slips (multiples of 7.2 deg) plus at most half a step.
    const double shortfall_deg = run.motor.commanded_deg() - run.motor.angle_deg();
    EXPECT_NEAR(shortfall_deg, static_cast<double>(run.motor.lost_steps()) * 1.8, 0.9 + 1e-6);
}

TEST(MotorSeed003, StallVcdShowsCommandedAndActualAngleDiverging) {
    ShieldRun run("thesis_fsm");
    Timeline timeline;
    Recorder recorder(timeline);
    recorder.trace_part(run.motor);
    recorder.trace_part(run.board.part("latch"));
    run.uno.uart(0).send("ARDS");
    for (int i = 1; i <= 40 && run.uno.read_ram_u8("bench_phase") != 4; ++i) run.board.run_until_seconds(i * 0.1);
    run.board.run_for_seconds(0.2);
    std::filesystem::create_directories(test::source_path("traces"));
    const std::string path = test::source_path("traces/motor_thesis_stall.vcd");
    VcdOptions options;
    options.end_cycle = run.uno.cycle();
    const VcdResult written = write_vcd(timeline, path, options);
    GtkwOptions view;  // gtkwave traces/motor_thesis_stall.gtkw
    view.fit_end_time = written.end_time;
    view.fit_timescale = written.timescale;
    write_gtkw(timeline, test::source_path("traces/motor_thesis_stall.gtkw"), path, view);

    const VcdDump dump = read_vcd(path);
    const auto& commanded = dump.at("motor.commanded_deg");
    const auto& actual = dump.at("motor.angle_deg");
    const auto& lost = dump.at("motor.lost_steps");
    ASSERT_FALSE(commanded.changes.empty());
    ASSERT_FALSE(actual.changes.empty());
    // In step at first, then apart by whole pole slips at the end.
    EXPECT_NEAR(std::stod(commanded.changes.front().value), std::stod(actual.changes.front().value), 1e-9);
    const double end_gap = std::stod(commanded.changes.back().value) - std::stod(actual.changes.back().value);
    EXPECT_GT(end_gap, 7.2);
    EXPECT_GT(std::stod(lost.changes.back().value), 0);
    ASSERT_NE(dump.find("motor.current_a_A"), nullptr);
    ASSERT_NE(dump.find("motor.speed_rpm"), nullptr);
}

}  // namespace
}  // namespace avrbench
