// The standard RAMPS boards' endstops against the firmware settings each
// board file says it matches (firmware/boards/ramps_home: X and Y homed
// the way Marlin reads its min endstops).
//
// Marlin 1.1/2.x defaults (ENDSTOPPULLUPS, *_MIN_ENDSTOP_INVERTING false:
// HIGH = triggered) on ramps-1.4 (normally-closed switches to GND): nothing
// triggered at rest, and homing from the carriages' start (100 mm) stops on
// the switches 2 mm inside the travel, 98 mm x 80 steps/mm = 7840 steps, with
// no finding. The inverted build on ramps-1.4-no-endstops (normally open)
// does the same; the optical variant matches Marlin's defaults too. And the
// mismatch the issue saw: Marlin's defaults on normally-open switches read
// every endstop triggered at rest and home nowhere.
#include <gtest/gtest.h>

#include <string>

#include "boards/Board.hpp"
#include "mcu/Mcu.hpp"
#include "parts/Axis.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

struct Homed {
    unsigned rest_triggered;
    unsigned x_steps, y_steps;
    double x_mm, y_mm;
    std::size_t findings;
};

Homed home(const std::string& board_name, const std::string& firmware) {
    Board board(load_board_file(board_name), {{"mega", test::firmware(firmware)}});
    // 2 x 7840 steps at 10 kHz: 1.57 s; 2 s is the bound.
    board.run_for_seconds(2.0);
    Mcu& mega = board.mcu("mega");
    EXPECT_EQ(mega.read_ram_u8("done"), 1) << board_name << " " << firmware;
    return {mega.read_ram_u8("rest_triggered"), mega.read_ram_u16("x_steps"), mega.read_ram_u16("y_steps"),
            board.part_as<Axis>("x").position_mm(), board.part_as<Axis>("y").position_mm(), board.findings().size()};
}

constexpr unsigned kStepsTo2mm = (100 - 2) * 80;

TEST(RampsEndstops, MarlinDefaultsOnTheStandardBoardHomeOntoTheSwitches) {
    const Homed h = home("ramps-1.4", "ramps_home");
    EXPECT_EQ(h.rest_triggered, 0u) << "M119 would report a triggered endstop at rest";
    EXPECT_EQ(h.x_steps, kStepsTo2mm);
    EXPECT_EQ(h.y_steps, kStepsTo2mm);
    EXPECT_DOUBLE_EQ(h.x_mm, 2.0);
    EXPECT_DOUBLE_EQ(h.y_mm, 2.0);
    EXPECT_EQ(h.findings, 0u) << "homing ran a carriage past its travel";
}

TEST(RampsEndstops, InvertedLogicOnTheNormallyOpenVariantHomesTheSame) {
    const Homed h = home("ramps-1.4-no-endstops", "ramps_home_inverted");
    EXPECT_EQ(h.rest_triggered, 0u);
    EXPECT_EQ(h.x_steps, kStepsTo2mm);
    EXPECT_EQ(h.y_steps, kStepsTo2mm);
    EXPECT_EQ(h.findings, 0u);
}

TEST(RampsEndstops, MarlinDefaultsOnOpticalEndstopsHomeOntoTheBeam) {
    const Homed h = home("ramps-1.4-optical-endstops", "ramps_home");
    EXPECT_EQ(h.rest_triggered, 0u);
    EXPECT_EQ(h.x_steps, kStepsTo2mm);
    EXPECT_EQ(h.y_steps, kStepsTo2mm);
    EXPECT_EQ(h.findings, 0u);
}

TEST(RampsEndstops, MarlinDefaultsOnNormallyOpenSwitchesReadEveryEndstopTriggered) {
    const Homed h = home("ramps-1.4-no-endstops", "ramps_home");
    EXPECT_EQ(h.rest_triggered, 7u);  // X, Y and Z
    EXPECT_EQ(h.x_steps, 0u);
    EXPECT_EQ(h.y_steps, 0u);
}

}  // namespace
}  // namespace avrbench
