// Heater and plant on a running firmware: the step response, steady state
// against duty, the energy balance, the heater's energy from its pin, and the
// traces. firmware/thermal/pwm_heater drives D10 at a fixed duty.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "parts/Fan.hpp"
#include "parts/Heater.hpp"
#include "parts/ThermalPlant.hpp"
#include "support/PinLog.hpp"
#include "thermal/ThermalTestSupport.hpp"
#include "trace/Recorder.hpp"
#include "trace/VcdReader.hpp"
#include "trace/VcdWriter.hpp"

namespace avrbench {
namespace {

TEST(ThermalPlant, SingleNodeStepResponseMatchesTheClosedForm) {
    // 40 W (12 V across 3.6 ohm) into C = 16.7 J/K with R_th = 1/0.068 = 14.706 K/W:
    // T = 25 + P R_th (1 - e^{-t/tau}), tau = R_th C = 245.59 s, P R_th = 588.24 K.
    auto board = test::thermal_board(test::kSingleNodeBoard, "thermal_pwm_full");
    test::PinLog gate(board->mcu(), "PB4");  // the heater gate as the MCU pin shows it
    auto& plant = board->part_as<ThermalPlant>("hotend");
    board->run_for_seconds(0.01);
    ASSERT_EQ(gate.edges().size(), 1u);  // switched on once, never off
    ASSERT_TRUE(gate.edges()[0].level);
    const Cycle on_at = gate.edges()[0].cycle;
    const double f = board->mcu().frequency_hz();
    for (double t : {5.0, 30.0, 100.0, 245.59}) {
        board->run_until_seconds(static_cast<double>(on_at) / f + t);
        const double elapsed = static_cast<double>(board->mcu().cycle() - on_at) / f;
        const double expected = 25.0 + 40.0 * (1.0 / 0.068) * (1.0 - std::exp(-elapsed / (16.7 / 0.068)));
        EXPECT_NEAR(plant.block_degC(), expected, 0.1) << "t = " << elapsed << " s";
        EXPECT_NEAR(plant.sensor_degC(), expected, 0.1);
    }
    // By hand at t = tau: 25 + 588.24 * (1 - 1/e) = 396.84 degC.
    EXPECT_NEAR(plant.block_degC(), 396.84, 0.1);
}

TEST(ThermalPlant, SteadyStateIsProportionalToDuty) {
    // A light block (C = 2 J/K, tau = 29.4 s) so 400 s is 13.6 tau. OCR2A = 63:
    // on 64 of 256 counts, duty 0.25, mean power 10 W: T_ss = 25 + 10 / 0.068
    // = 172.06 degC. Ripple at 61 Hz: 30 W * 4.1 ms / 2 J/K = 0.06 K peak to peak.
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: custom, heat_capacity: 2J/K, ambient_conductance: 0.068W/K, sensor_time_constant: 0s}
  heater: {type: heater, preset: cartridge_40w_12v}
nets:
  hotend_body: [hotend.body, heater.body]
  gate: [mega.PB4, heater.gate]
)";
    auto board = test::thermal_board(yaml, "thermal_pwm_quarter");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    auto& heater = board->part_as<Heater>("heater");
    board->run_for_seconds(400);
    EXPECT_NEAR(plant.block_degC(), 172.06, 0.1);
    const Cycle start = heater.on_cycles();
    const Cycle from = board->mcu().cycle();
    board->run_for_seconds(10);
    const double duty = static_cast<double>(heater.on_cycles() - start) / static_cast<double>(board->mcu().cycle() - from);
    EXPECT_NEAR(duty, 64.0 / 256.0, 0.001);
    EXPECT_NEAR(plant.block_degC(), 172.06, 0.1);
}

TEST(ThermalPlant, SteadyStateAtHalfDutyWithTheFanOn) {
    // OCR2A = 127: duty 0.5, 20 W. The fan (D9 on) raises the loss to Marlin's
    // MPC_AMBIENT_XFER_COEFF_FAN255 0.097 W/K: T_ss = 25 + 20 / 0.097 = 231.19 degC.
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: custom, heat_capacity: 2J/K, ambient_conductance: 0.068W/K, ambient_conductance_fan: 0.097W/K, sensor_time_constant: 0s}
  heater: {type: heater, preset: cartridge_40w_12v}
  fan: {type: fan}
nets:
  hotend_body: [hotend.body, heater.body, fan.body]
  gate: [mega.PB4, heater.gate]
  fan: [mega.PH6, fan.pwm]
)";
    auto board = test::thermal_board(yaml, "thermal_pwm_half_fan");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    board->run_for_seconds(300);
    EXPECT_DOUBLE_EQ(plant.fan_speed(), 1.0);
    EXPECT_NEAR(plant.block_degC(), 231.19, 0.1);
}

TEST(HeaterEnergy, EqualsStoredPlusLost) {
    // The e3d_v6 preset (block + sensor bead) with 25 % duty for 300 s: the
    // heater's energy, integrated between its gate edges, equals what the
    // plant stored plus what it lost, within 0.5 % (in fact to rounding).
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: e3d_v6}
  heater: {type: heater, preset: cartridge_40w_12v}
nets:
  hotend_body: [hotend.body, heater.body]
  gate: [mega.PB4, heater.gate]
)";
    auto board = test::thermal_board(yaml, "thermal_pwm_quarter");
    test::PinLog gate(board->mcu(), "PB4");  // the heater gate as the MCU pin shows it
    auto& plant = board->part_as<ThermalPlant>("hotend");
    auto& heater = board->part_as<Heater>("heater");
    board->run_for_seconds(300);
    const double in = heater.energy_J();
    // Independent of the heater: on-time from the MCU pin's own edges, times 40 W.
    const double from_pin = static_cast<double>(gate.high_cycles_until(board->mcu().cycle())) / 16e6 * 40.0;
    EXPECT_NEAR(in, from_pin, 1e-9 * in);
    // About 300 s * 10 W = 3000 J.
    EXPECT_NEAR(in, 3000.0, 15.0);
    EXPECT_NEAR(plant.energy_in_J(), in, 1e-9 * in);
    const double stored = plant.energy_stored_J();
    const double lost = plant.energy_lost_J();
    EXPECT_GT(stored, 0);
    EXPECT_GT(lost, 0);
    EXPECT_NEAR(stored + lost, in, 0.005 * in);
    EXPECT_NEAR(stored + lost, in, 1e-6 * in);
    // Stored is C * (T - 25) by definition: 16.7 J/K times the block's rise.
    EXPECT_NEAR(stored, 16.7 * (plant.block_degC() - 25.0), 1e-6 * stored);
}

TEST(HeaterEnergy, PowerFollowsSupplyAndResistance) {
    // The presets: 12 V / 3.6 ohm = 40 W; 24 V / 14.4 ohm = 40 W; bed 12 V / 1.2 ohm = 120 W;
    // a series 0.4 ohm on the 12 V cartridge: 12^2 * 3.6 / 4.0^2 = 32.4 W.
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  plant: {type: thermal_plant, preset: heated_bed}
  h12: {type: heater, preset: cartridge_40w_12v}
  h24: {type: heater, preset: cartridge_40w_24v}
  bed: {type: heater, preset: bed_12v}
  lossy: {type: heater, preset: cartridge_40w_12v, series_resistance: 0.4ohm}
  low: {type: heater, preset: custom, supply: 24V, resistance: 4.8ohm, gate_active: low}
nets:
  plant_body: [plant.body, h12.body, h24.body, bed.body, lossy.body, low.body]
)";
    auto board = test::thermal_board(yaml, "thermal_pwm_off");
    EXPECT_NEAR(board->part_as<Heater>("h12").power_on_W(), 40.0, 1e-9);
    EXPECT_NEAR(board->part_as<Heater>("h24").power_on_W(), 40.0, 1e-9);
    EXPECT_NEAR(board->part_as<Heater>("bed").power_on_W(), 120.0, 1e-9);
    EXPECT_NEAR(board->part_as<Heater>("lossy").power_on_W(), 32.4, 1e-9);
    // 24^2 / 4.8 = 120 W; an unwired active-low gate reads low: on.
    EXPECT_NEAR(board->part_as<Heater>("low").power_on_W(), 120.0, 1e-9);
    EXPECT_TRUE(board->part_as<Heater>("low").on());
}

TEST(HeaterEnergy, ANegativeSupplyIsNamedAsSuch) {
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  plant: {type: thermal_plant, preset: heated_bed}
  h: {type: heater, preset: custom, supply: -12V, resistance: 4.8ohm}
nets:
  plant_body: [plant.body, h.body]
)";
    try {
        test::thermal_board(yaml, "thermal_pwm_off");
        ADD_FAILURE() << "a negative supply was accepted";
    } catch (const BadInput& e) {
        // Voltages are 0..1000 V (dimension_range), reported at the value's line.
        EXPECT_NE(std::string(e.what()).find("thermal-test.yaml:6: part 'h': supply: '-12V' is outside 0 .. 1000 V"), std::string::npos)
            << e.what();
    }
}

TEST(HeaterEnergy, ActiveLowGateInvertsTheDuty) {
    // A P-MOSFET (or inverting driver) stage: gate low = on. The firmware's
    // 64/256 high time becomes 192/256 = 0.75 on-time, 30 W mean.
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: e3d_v6}
  heater: {type: heater, preset: cartridge_40w_12v, gate_active: low}
nets:
  hotend_body: [hotend.body, heater.body]
  gate: [mega.PB4, heater.gate]
)";
    auto board = test::thermal_board(yaml, "thermal_pwm_quarter");
    auto& heater = board->part_as<Heater>("heater");
    board->run_for_seconds(1.0);
    const Cycle on0 = heater.on_cycles(), c0 = board->mcu().cycle();
    board->run_for_seconds(10.0);
    const double duty = static_cast<double>(heater.on_cycles() - on0) / static_cast<double>(board->mcu().cycle() - c0);
    EXPECT_NEAR(duty, 192.0 / 256.0, 0.001);
}

std::string board_error(const std::string& yaml) {
    try {
        test::thermal_board(yaml, "thermal_pwm_off");
    } catch (const BadInput& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(ThermalBoardFile, WiringMistakesNameFileAndLine) {
    const std::string head = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: e3d_v6}
  x_driver: {type: step_dir_driver}
)";
    EXPECT_EQ(board_error(head + "  heater: {type: heater}\nnets:\n  body: [x_driver.steps, heater.body]\n"),
              "thermal-test.yaml:9: net 'body' joins a steps port (x_driver.steps) and a thermal port (heater.body)");
    EXPECT_EQ(board_error(head + "  heater: {type: heater}\n"),
              "thermal-test.yaml:7: part 'heater' (heater): port 'body' is not connected: join it to the thermal_plant "
              "it heats in nets:");
    EXPECT_EQ(board_error(head + "  heater: {type: heater}\n  t0: {type: thermistor}\nnets:\n  body: [heater.body, t0.body]\n"),
              "thermal-test.yaml:10: net 'body' has no part providing its thermal port (heater.body needs one, e.g. a "
              "thermal_plant's body)");
    // An analog output shares its net with the MCU pins whose ADC samples it, nothing else.
    EXPECT_EQ(board_error(head + "  t0: {type: thermistor}\nnets:\n  body: [hotend.body, t0.body]\n"
                                 "  adc: [t0.out, x_driver.step]\n"),
              "thermal-test.yaml:10: net 'adc' joins the analog output t0.out and the digital pin x_driver.step: an "
              "analog net holds MCU pins only");
    EXPECT_EQ(board_error(head + "  heater: {type: heater, node: surface}\nnets:\n  body: [hotend.body, heater.body]\n"),
              "thermal-test.yaml:7: part 'heater': plant 'hotend' has no node 'surface' to heat (block)");
    EXPECT_EQ(board_error(head + "  plant2: {type: thermal_plant, preset: custom, heat_capacity: 5J/K}\n"),
              "thermal-test.yaml:7: part 'plant2': a custom plant needs ambient_conductance");
    EXPECT_EQ(board_error(head + "  plant2: {type: thermal_plant, ambient_conductance: 2K/W}\n"),
              "thermal-test.yaml:7: part 'plant2': ambient_conductance: '2K/W' is a thermal resistance, expected a "
              "thermal conductance (W/K, mW/K)");
}

TEST(ThermalTrace, TemperaturesAndDutyAreRealVcdSignals) {
    auto board = test::thermal_board(test::kSingleNodeBoard, "thermal_pwm_quarter");
    Timeline timeline;
    Recorder recorder(timeline);
    for (Part* p : board->parts()) recorder.trace_part(*p);
    board->run_for_seconds(2.0);
    const auto dir = std::filesystem::temp_directory_path() / "avrbench-thermal-trace";
    std::filesystem::create_directories(dir);
    const auto path = (dir / "thermal.vcd").string();
    VcdOptions options;
    options.end_cycle = board->mcu().cycle();
    write_vcd(timeline, path, options);
    const VcdDump dump = read_vcd(path);
    const VcdVariable& block = dump.at("hotend.block_degC");
    EXPECT_EQ(block.type, "real");
    // One value per 100 ms sample: 20 in 2 s, plus the initial one.
    EXPECT_GE(block.changes.size(), 20u);
    EXPECT_DOUBLE_EQ(std::stod(block.changes.front().value), 25.0);
    EXPECT_GT(std::stod(block.changes.back().value), 25.5);
    const VcdVariable& duty = dump.at("heater.duty");
    EXPECT_EQ(duty.type, "real");
    // After the first sample the duty is 64/256 (0.25) to within one PWM period per 100 ms.
    EXPECT_NEAR(std::stod(duty.changes.back().value), 0.25, 0.04);
    EXPECT_EQ(dump.at("heater.on").type, "wire");
    EXPECT_EQ(dump.at("t0.volts").type, "real");
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace avrbench
