// A fan's tachometer and the inductive (PINDA) probe on the Einsy RAMBo's
// pins, read by our own firmware (firmware/boards/einsy_sensors/main.c) as
// Prusa-Firmware wires them. Expected counts are worked out beside them.
#include <gtest/gtest.h>

#include <string>

#include "boards/Board.hpp"
#include "parts/Fan.hpp"
#include "parts/InductiveProbe.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

// Z at 400 steps/mm (Prusa MK3S: 3200/8), 5 mm above the bed; the probe
// switches with the nozzle 0.999 mm above the bed under it (just under 1 mm,
// so a whole step decides it). The hot end fan: 5000 rpm, two tachometer
// pulses per revolution, 0.5 s spin-up time constant (the part's defaults).
std::string sensors_board_text(const std::string& probe_extra) {
    return R"(
board: einsy-sensors
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  z_driver: {type: step_dir_driver, preset: tmc2208, microsteps: 16}
  z: {type: linear_axis, steps_per_mm: 400, travel: 210mm, start_position: 5mm}
  pinda: {type: inductive_probe, trigger_height: 0.999mm)" + probe_extra + R"(}
  hotend_fan: {type: fan}
nets:
  z_step: [mega.PC2, z_driver.step]
  z_dir: [mega.PL2, z_driver.dir]
  z_enable: [mega.PA5, z_driver.enable]
  z_motion: [z_driver.steps, z.drive]
  z_carriage: [z.carriage, pinda.z]
  pinda: [mega.PB4, pinda.out]
  fan_gate: [mega.PH5, hotend_fan.pwm]
  fan_tach: [mega.PE6, hotend_fan.tach]
)";
}

Board make_sensors_board(const std::string& probe_extra) {
    return Board(parse_board_text(sensors_board_text(probe_extra), "einsy-sensors.yaml"), {{"mega", test::firmware("einsy_sensors")}});
}

TEST(InductiveProbe, SwitchesAtItsHeightAboveAFlatBed) {
    Board board = make_sensors_board("");
    board.run_for_seconds(1);
    ASSERT_EQ(board.mcu().read_ram_u8("done"), 1);
    // 5 - k / 400 <= 0.999 mm first for k = 1601 (k = 1600 leaves 1.000 mm).
    EXPECT_EQ(board.mcu().read_ram_u16("probe_steps"), 1601);
    EXPECT_TRUE(dynamic_cast<InductiveProbe&>(board.part("pinda")).triggered());
}

TEST(InductiveProbe, MeasuresTheBedsHeightMapUnderIt) {
    // A 2 x 2 map over a 100 x 100 mm bed, the probe (no X/Y axes joined) at
    // its offset (50, 50) mm, the middle: bilinear = (0 + 0.4 + 0.2 + 0.6) / 4
    // = 0.3 mm. 5 - k / 400 <= 1.299 mm first for k = 1481 (1480.4 rounded up).
    Board board = make_sensors_board(", offset_x: 50mm, offset_y: 50mm, bed_size_x: 100mm, bed_size_y: 100mm, bed_heights: '0 0.4 / 0.2 0.6'");
    board.run_for_seconds(1);
    EXPECT_EQ(board.mcu().read_ram_u16("probe_steps"), 1481);
    auto& probe = dynamic_cast<InductiveProbe&>(board.part("pinda"));
    EXPECT_NEAR(probe.bed_height_m(0.05, 0.05), 0.3e-3, 1e-12);
    EXPECT_NEAR(probe.bed_height_m(0.0, 0.1), 0.2e-3, 1e-12);  // a corner: its own value
}

TEST(Fan, TachometerPulsesFollowTheSpeed) {
    Board board = make_sensors_board("");
    board.run_for_seconds(2);
    const unsigned at_2s = board.mcu().read_ram_u16("tach_falls");
    board.run_for_seconds(1);
    const unsigned at_3s = board.mcu().read_ram_u16("tach_falls");
    // Pulses per second at speed s: s * 5000 / 60 * 2. With s = 1 - e^(-t/0.5)
    // from power-up, the pulses from 2 s to 3 s are
    // 166.67 * (1 - 0.5 * (e^-4 - e^-6)) = 165.35.
    EXPECT_NEAR(static_cast<double>(at_3s - at_2s), 165.35, 1.0);
    EXPECT_NEAR(dynamic_cast<Fan&>(board.part("hotend_fan")).rpm(), 5000 * (1 - std::exp(-6.0)), 1.0);
}

TEST(Fan, AStoppedFansTachometerFallsSilent) {
    Board board = make_sensors_board("");
    board.run_for_seconds(3);
    board.part("hotend_fan").inject_fault_at_seconds("stopped", 3.0);
    // Spinning down from ~1 at 3 s with tau 0.5 s, it is under 1 % of full
    // speed (no pulses) after 0.5 * ln(100) = 2.3 s: none from 6 s to 7 s.
    board.run_for_seconds(3);
    const unsigned at_6s = board.mcu().read_ram_u16("tach_falls");
    board.run_for_seconds(1);
    EXPECT_EQ(board.mcu().read_ram_u16("tach_falls"), at_6s);
}

}  // namespace
}  // namespace avrbench
