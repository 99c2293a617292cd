// The limit switch model with limit_probe: a homing move onto the X switch
// and back off (firmware/boards/limit_probe/main.c).
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "parts/Axis.hpp"
#include "parts/LimitSwitch.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

// 250 steps/mm (grbl default), carriage at 1 mm, switch at 0.5 mm with
// 0.05 mm hysteresis.
// `switch_extra` (", contact: NC, ...") overrides the switch's defaults:
// a board file may not name a key twice.
std::string board_text(const std::string& switch_extra) {
    std::vector<std::pair<std::string, std::string>> params = {
        {"type", "limit_switch"}, {"side", "min"}, {"position", "0.5mm"}, {"hysteresis", "0.05mm"},
        {"contact", "NO"}, {"switched_to", "gnd"}, {"pull", "internal_up"}};
    std::stringstream extras(switch_extra);
    std::string item;
    while (std::getline(extras, item, ',')) {
        const auto colon = item.find(':');
        if (colon == std::string::npos) continue;
        auto trim = [](std::string t) {
            t.erase(0, t.find_first_not_of(' '));
            t.erase(t.find_last_not_of(' ') + 1);
            return t;
        };
        const std::string key = trim(item.substr(0, colon)), value = trim(item.substr(colon + 1));
        bool replaced = false;
        for (auto& [k, v] : params) {
            if (k == key) {
                v = value;
                replaced = true;
            }
        }
        if (!replaced) params.emplace_back(key, value);
    }
    std::string limit;
    for (const auto& [k, v] : params) limit += (limit.empty() ? "" : ", ") + k + ": " + v;
    return R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 16}
  x: {type: linear_axis, steps_per_mm: 250, travel: 200mm, start_position: 1mm}
  x_limit: {)" + limit + R"(}
nets:
  x_driver_steps: [x_driver.steps, x.drive]
  x_carriage: [x.carriage, x_limit.axis]
  x_step: [uno.PD2, x_driver.step]
  x_dir: [uno.PD5, x_driver.dir]
  enable: [uno.PB0, x_driver.enable]
  x_limit: [uno.PB1, x_limit.out]
)";
}

struct Homing {
    Board board;
    explicit Homing(const std::string& switch_extra)
        : board(parse_board_text(board_text(switch_extra), "limit-test.yaml"), {{"uno", test::firmware("limit_probe")}}) {
        board.run_for_seconds(0.1);
        EXPECT_EQ(board.mcu().read_ram_u8("done"), 1);
    }
    std::uint16_t steps_to_trip() const { return board.mcus()[0]->read_ram_u16("steps_to_trip"); }
    std::uint16_t steps_to_release() const { return board.mcus()[0]->read_ram_u16("steps_to_release"); }
    std::uint8_t edges() const { return board.mcus()[0]->read_ram_u8("pcint_edges"); }
};

TEST(LimitSwitch, TripsAtItsPositionAndReleasesPastTheHysteresis) {
    Homing h("");
    // From 1 mm to 0.5 mm at 250 steps/mm: 0.5 * 250 = 125 steps, the switch
    // closing on the 125th (at <= 0.5 mm).
    EXPECT_EQ(h.steps_to_trip(), 125);
    // It opens once the carriage is past 0.5 + 0.05 = 0.55 mm: 0.05 * 250 =
    // 12.5 steps, so on the 13th step back.
    EXPECT_EQ(h.steps_to_release(), 13);
    // Without bounce: one edge closing, one opening.
    EXPECT_EQ(h.edges(), 2);
    auto& sw = h.board.part_as<LimitSwitch>("x_limit");
    EXPECT_EQ(sw.trips(), 1u);
    EXPECT_FALSE(sw.triggered());
    EXPECT_NEAR(h.board.part_as<Axis>("x").position_mm(), 0.5 + 13.0 / 250.0, 1e-9);
}

TEST(LimitSwitch, BouncesAsConfiguredAndDeterministically) {
    Homing a(", bounce: 1ms, bounce_edges: 4, seed: 7");
    Homing b(", bounce: 1ms, bounce_edges: 4, seed: 7");
    // Bounce adds make/break pairs on both transitions, so the firmware's
    // pin-change interrupt sees more than the clean 2 edges...
    EXPECT_GT(a.edges(), 2);
    // ...an even number (the contact ends where it settles each time)...
    EXPECT_EQ(a.edges() % 2, 0);
    // ...at most 1 + 2 * 4 per transition (bounce_edges pairs) ...
    EXPECT_LE(a.edges(), 2 * (1 + 2 * 4));
    // ...and the same seed gives the same bounce.
    EXPECT_EQ(a.edges(), b.edges());
    EXPECT_EQ(a.board.part_as<LimitSwitch>("x_limit").contact_transitions(),
              b.board.part_as<LimitSwitch>("x_limit").contact_transitions());
    // Homing still stops at the first closure.
    EXPECT_EQ(a.steps_to_trip(), 125);
}

TEST(LimitSwitch, NormallyClosedSwitchToVccReadsTheSameAfterInversion) {
    // NC to VCC with an external pull-down: open (triggered) reads 0 through the pull-down, closed reads 1:
    // the same logic levels as NO-to-GND with a pull-up, so the firmware homes the same.
    Homing h(", contact: NC, switched_to: vcc, pull: external_down");
    EXPECT_EQ(h.steps_to_trip(), 125);
    EXPECT_EQ(h.steps_to_release(), 13);
}

TEST(LimitSwitch, PushPullSensorDrivesBothLevelsAgainstThePullUp) {
    // An optical endstop's output stage drives low while the beam is
    // interrupted (here wired active low to match the firmware) and high while
    // it is clear: strong both ways, so the firmware's pull-up changes nothing.
    Homing h(", contact: NC, switched_to: vcc, pull: push_pull");
    EXPECT_EQ(h.steps_to_trip(), 125);
    EXPECT_EQ(h.steps_to_release(), 13);
    EXPECT_TRUE(h.board.findings().empty());
}

// Faults, injected at power-on: limit_probe (firmware/boards/limit_probe)
// steps towards the switch while PB1 reads 1 and back while it reads 0,
// each loop capped at 60000 steps.
TEST(LimitSwitch, StuckClosedReadsClosedWhereverTheCarriageIs) {
    Board board(parse_board_text(board_text(""), "limit-test.yaml"), {{"uno", test::firmware("limit_probe")}});
    board.part("x_limit").inject_fault("stuck_closed", 0);
    board.run_for_seconds(2.0);
    ASSERT_EQ(board.mcu().read_ram_u8("done"), 1);
    // Closed before the first step (the carriage at 1 mm, the switch at 0.5 mm)...
    EXPECT_EQ(board.mcus()[0]->read_ram_u16("steps_to_trip"), 0);
    // ...and still closed after backing off 60000 steps (240 mm).
    EXPECT_EQ(board.mcus()[0]->read_ram_u16("steps_to_release"), 60000);
    EXPECT_TRUE(board.part_as<LimitSwitch>("x_limit").contact_closed());
}

TEST(LimitSwitch, StuckOpenNeverTripsAndNoneRepairs) {
    Board board(parse_board_text(board_text(""), "limit-test.yaml"), {{"uno", test::firmware("limit_probe")}});
    auto& sw = board.part_as<LimitSwitch>("x_limit");
    sw.inject_fault("stuck_open", 0);
    board.run_for_seconds(0.05);  // ~2000 steps: the carriage is past the switch (125 steps away)
    EXPECT_TRUE(sw.triggered());   // where the carriage is...
    EXPECT_FALSE(sw.contact_closed());  // ...but the contact stays open
    EXPECT_EQ(board.pin("uno.PB1").level(), 1);  // the pull-up
    sw.inject_fault("none", board.mcu().cycle());
    board.run_for_seconds(0.001);
    EXPECT_TRUE(sw.contact_closed());
    EXPECT_EQ(board.pin("uno.PB1").level(), 0);
}

}  // namespace
}  // namespace avrbench
