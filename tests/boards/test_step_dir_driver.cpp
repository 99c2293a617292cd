// The A4988 model on the UNO + CNC shield board, driven by step_pattern: a
// firmware that emits a fixed STEP/DIR/ENABLE sequence with deliberate faults
// (firmware/boards/step_pattern/main.c documents each phase and its numbers).
#include <gtest/gtest.h>

#include "boards/Board.hpp"
#include "parts/Axis.hpp"
#include "parts/StepDirDriver.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"

namespace avrbench {
namespace {

std::unique_ptr<Board> uno_with(const std::string& firmware) {
    return Board::from_file(test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml"),
                            {{"uno", test::firmware(firmware)}});
}

std::vector<Finding> of_kind(const std::vector<Finding>& all, FindingKind kind) {
    std::vector<Finding> out;
    for (const auto& f : all) {
        if (f.kind == kind) out.push_back(f);
    }
    return out;
}

struct PatternRun {
    std::unique_ptr<Board> board = uno_with("step_pattern");
    test::PinLog step{board->mcu("uno"), "PD2"};
    PatternRun() {
        board->run_for_seconds(0.05);  // the whole pattern takes < 1 ms
        EXPECT_EQ(board->mcu("uno").read_ram_u8("phase"), 8) << "the pattern did not finish";
    }
    StepDirDriver& driver() { return board->part_as<StepDirDriver>("x_driver"); }
};

TEST(StepDirDriver, CountsStepsAndIgnoresThemWhileDisabled) {
    PatternRun run;
    // step_pattern header: 155 active edges while enabled, 30 while disabled.
    EXPECT_EQ(run.driver().steps_taken(), 155u);
    EXPECT_EQ(run.driver().steps_ignored(), 30u);
    EXPECT_EQ(run.step.rises().size(), 185u);  // the pin saw every pulse: 155 + 30
    // Net motion: 49 steps with DIR high at 1/16 microstepping (board:
    // microsteps 16). The CNC shield board counts DIR low as + (grbl drives
    // DIR high for negative moves), so that is -49 steps.
    auto& x = run.board->part_as<Axis>("x");
    EXPECT_DOUBLE_EQ(x.position_steps(), -49.0);
    // 250 steps/mm (grbl default): -49 steps from the 100 mm start = 99.804 mm.
    EXPECT_NEAR(x.position_mm(), 100.0 - 49.0 / 250.0, 1e-9);
}

TEST(StepDirDriver, ReportsTheShortPulseAtItsFallingEdge) {
    PatternRun run;
    const auto shorts = of_kind(run.board->findings(), StepDirDriver::kStepHighTooShort);
    ASSERT_EQ(shorts.size(), 1u);
    // The pin trace has the pulse: find the one high interval shorter than
    // 16 cycles (1 us at 16 MHz); the finding carries its falling edge.
    Cycle falling = 0, width = 0;
    const auto& edges = run.step.edges();
    for (std::size_t i = 1; i < edges.size(); ++i) {
        if (!edges[i].level && edges[i - 1].level && edges[i].cycle - edges[i - 1].cycle < 16) {
            falling = edges[i].cycle;
            width = edges[i].cycle - edges[i - 1].cycle;
        }
    }
    ASSERT_NE(falling, 0u);
    EXPECT_EQ(width, 8u);  // 6 delay cycles + the 2-cycle CBI (step_pattern phase 2)
    EXPECT_EQ(shorts[0].cycle, falling);
    EXPECT_EQ(shorts[0].source, "x_driver");
}

TEST(StepDirDriver, ReportsDirSetupAndHoldViolations) {
    PatternRun run;
    const auto setup = of_kind(run.board->findings(), StepDirDriver::kDirSetupViolation);
    const auto hold = of_kind(run.board->findings(), StepDirDriver::kDirHoldViolation);
    ASSERT_EQ(setup.size(), 1u);
    ASSERT_EQ(hold.size(), 1u);
    // Both happen 2 cycles (one SBI/CBI) from the STEP edge; the A4988 needs
    // 200 ns = 3.2 cycles, so 4 cycles.
    EXPECT_NE(setup[0].detail.find("2 cycles before"), std::string::npos) << setup[0].detail;
    EXPECT_NE(hold[0].detail.find("2 cycles after"), std::string::npos) << hold[0].detail;
}

TEST(StepDirDriver, ReportsShortLowTimeAndExcessRate) {
    PatternRun run;
    const auto low = of_kind(run.board->findings(), StepDirDriver::kStepLowTooShort);
    const auto rate = of_kind(run.board->findings(), StepDirDriver::kStepRateTooHigh);
    ASSERT_EQ(low.size(), 1u);
    // Phase 7: 2 delay cycles + the 2-cycle SBI = 4 cycles low.
    EXPECT_NE(low[0].detail.find("inactive for 4 cycles"), std::string::npos) << low[0].detail;
    // Phase 7's period is 32 + 4 = 36 cycles: 16e6 / 36 = 444 444 steps/s,
    // within the A4988's 500 kHz (1 / (1 us + 1 us)); no other period is shorter.
    EXPECT_EQ(rate.size(), 0u);
    EXPECT_NEAR(run.driver().peak_step_rate_hz(), 16e6 / 36.0, 1.0);
}

TEST(StepDirDriver, Drv8825PresetCatchesTheRateTheA4988Allows) {
    // The same pins with a DRV8825: 250 kHz maximum and 1.9 us (30.4 -> 31
    // cycles) minimum high and low (TI SLVSA73 §7.6).
    const std::string board_text = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  x_driver: {type: step_dir_driver, preset: drv8825, microsteps: 32}
nets:
  x_step: [uno.PD2, x_driver.step]
  x_dir: [uno.PD5, x_driver.dir]
  enable: [uno.PB0, x_driver.enable]
)";
    Board board(parse_board_text(board_text, "drv8825-test.yaml"), {{"uno", test::firmware("step_pattern")}});
    board.run_for_seconds(0.05);
    const auto findings = board.findings();
    const auto rate = of_kind(findings, StepDirDriver::kStepRateTooHigh);
    ASSERT_EQ(rate.size(), 1u);
    EXPECT_NE(rate[0].detail.find("STEP period 36 cycles"), std::string::npos) << rate[0].detail;
    // Phase 2's 8-cycle pulse and phase 7's 4-cycle low time violate 31 cycles too.
    EXPECT_EQ(of_kind(findings, StepDirDriver::kStepHighTooShort).size(), 1u);
    EXPECT_EQ(of_kind(findings, StepDirDriver::kStepLowTooShort).size(), 1u);
    // 650 ns setup/hold = 10.4 -> 11 cycles: the 2-cycle DIR changes violate both.
    EXPECT_EQ(of_kind(findings, StepDirDriver::kDirSetupViolation).size(), 1u);
    EXPECT_EQ(of_kind(findings, StepDirDriver::kDirHoldViolation).size(), 1u);
}

TEST(StepDirDriver, NoFindingsForGoodSteps) {
    PatternRun run;
    // Exactly the four faults the pattern contains, nothing for the 180 good pulses.
    EXPECT_EQ(run.board->findings().size(), 4u);
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(StepDirDriver, EachMinimumIsPinnedOnBothSides) {
    // firmware/boards/step_boundaries: each A4988 minimum met exactly (16
    // cycles STEP high, 16 low, 4 of DIR setup, 4 of hold: no finding) and
    // missed by one cycle (15, 15, 3, 3: one finding each).
    std::unique_ptr<Board> board = uno_with("step_boundaries");
    board->run_for_seconds(0.01);
    ASSERT_EQ(board->mcu().read_ram_u8("done"), 1);
    std::vector<std::string> details;
    for (const auto& f : board->findings()) details.push_back(f.kind.name() + ": " + f.detail);
    EXPECT_EQ(details, (std::vector<std::string>{
                           "step-high-too-short: STEP active for 15 cycles (0.938 us); a4988 needs 16 cycles",
                           "step-low-too-short: STEP inactive for 15 cycles before this edge; a4988 needs 16 cycles",
                           "dir-setup-violation: DIR changed 3 cycles before the STEP edge; a4988 needs 4 cycles of setup",
                           "dir-hold-violation: DIR changed 3 cycles after the STEP edge; a4988 needs 4 cycles of hold"}));
}

}  // namespace
}  // namespace avrbench
