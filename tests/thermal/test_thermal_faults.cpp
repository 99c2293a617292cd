// Every injectable fault, and what its physics does to the readings:
// thermistor open / shorted / detached, heater disconnected / stuck on, fan
// stopped. Faults are injected at a cycle through the C++ API (the same
// names a scenario file uses: Part::inject_fault).
#include <gtest/gtest.h>

#include <cmath>

#include "parts/Fan.hpp"
#include "parts/Heater.hpp"
#include "parts/ThermalPlant.hpp"
#include "parts/Thermistor.hpp"
#include "thermal/ThermalTestSupport.hpp"

namespace avrbench {
namespace {

constexpr double kTau = 16.7 / 0.068;  // single-node board: 245.59 s
constexpr double kRise = 40.0 / 0.068; // 588.24 K at full power

TEST(ThermalFault, OpenThermistorReadsFullScaleAndTripsMintemp) {
    auto board = test::ramps_board("thermal_runaway");
    board->part_as<Thermistor>("hotend_thermistor").inject(Thermistor::Fault::Open, board->mcu().cycles_from_seconds(2.0));
    board->run_for_seconds(1.0);
    EXPECT_EQ(board->mcu().read_ram_u8("error"), 0);
    board->run_for_seconds(1.5);
    // Open NTC on the lower leg: the pin sits at the reference, 5 V -> code 1023
    // (1024 clamped) in all 16 samples.
    EXPECT_EQ(board->mcu().read_ram_u16("adc_sum"), 16u * 1023u);
    // R = 4700 * 1023 / 1 = 4.8 Mohm -> -44.9 degC on the EPCOS curve: MINTEMP.
    EXPECT_NEAR(test::read_i16(board->mcu(), "temp_x10"), -449, 5);
    EXPECT_EQ(board->mcu().read_ram_u8("error"), 3) << "MINTEMP";
    EXPECT_FALSE(board->part_as<Heater>("hotend_heater").on());
}

TEST(ThermalFault, ShortedThermistorReadsZeroAndTripsMaxtemp) {
    auto board = test::ramps_board("thermal_runaway");
    board->part_as<Thermistor>("hotend_thermistor").inject_fault("shorted", board->mcu().cycles_from_seconds(2.0));
    board->run_for_seconds(2.5);
    EXPECT_EQ(board->mcu().read_ram_u16("adc_sum"), 0u);  // 0 V at the pin
    EXPECT_EQ(board->mcu().read_ram_u8("error"), 4) << "MAXTEMP";
    EXPECT_FALSE(board->part_as<Heater>("hotend_heater").on());
}

TEST(ThermalFault, DetachedThermistorFollowsAmbientWhileTheBlockHeats) {
    // e3d_v6 plant at full power; detached at 60 s the bead relaxes to ambient
    // with its own tau = 1/0.22 s: T = 25 + (T_d - 25) e^{-t * 0.22}.
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: e3d_v6}
  heater: {type: heater, preset: cartridge_40w_12v}
  t0: {type: thermistor, preset: epcos_b57560g104f}
nets:
  hotend_body: [hotend.body, heater.body, t0.body]
  t0_adc: [mega.PK5, t0.out]
  gate: [mega.PB4, heater.gate]
)";
    auto board = test::thermal_board(yaml, "thermal_pwm_full");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    auto& t0 = board->part_as<Thermistor>("t0");
    const Cycle at = board->mcu().cycles_from_seconds(60.0);
    t0.inject(Thermistor::Fault::Detached, at);
    board->run_until_seconds(60.0);
    const double bead_at_detach = plant.sensor_degC();
    const double block_at_detach = plant.block_degC();
    EXPECT_GT(bead_at_detach, 100.0);
    board->run_until_seconds(70.0);
    const double t = static_cast<double>(board->mcu().cycle() - at) / 16e6;
    EXPECT_NEAR(plant.sensor_degC(), 25.0 + (bead_at_detach - 25.0) * std::exp(-0.22 * t), 0.1);
    EXPECT_GT(plant.block_degC(), block_at_detach + 10.0);  // still heating at 40 W
    // What the firmware reads follows the bead: the 16-sample sum of A13.
    const double volts = t0.divider_volts(plant.sensor_degC());
    EXPECT_NEAR(board->mcu().read_ram_u16("adc_sum") / 16.0, volts * 1024 / 5, 2.0);
    // Re-attached at 70 s, it follows the block again: 30 s (6.6 tau) later it
    // is within 190 K * e^{-6.6} = 0.26 K of a bead that never came off (a
    // twin board without the fault); the block never noticed.
    t0.inject(Thermistor::Fault::None, board->mcu().cycle());
    board->run_until_seconds(100.0);
    auto twin = test::thermal_board(yaml, "thermal_pwm_full");
    twin->run_until_seconds(100.0);
    ASSERT_EQ(twin->mcu().cycle(), board->mcu().cycle());
    auto& twin_plant = twin->part_as<ThermalPlant>("hotend");
    EXPECT_NEAR(plant.sensor_degC(), twin_plant.sensor_degC(), 0.3);
    EXPECT_NEAR(plant.block_degC(), twin_plant.block_degC(), 1e-9);
}

TEST(HeaterFault, DisconnectedHeaterLetsTheBlockCoolExponentially) {
    auto board = test::thermal_board(test::kSingleNodeBoard, "thermal_pwm_full");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    auto& heater = board->part_as<Heater>("heater");
    const Cycle at = board->mcu().cycles_from_seconds(60.0);
    heater.inject(Heater::Fault::Disconnected, at);
    board->run_until_seconds(60.0);
    const double hot = plant.block_degC();
    const double energy = heater.energy_J();
    board->run_for_seconds(60.0);
    const double t = static_cast<double>(board->mcu().cycle() - at) / 16e6;
    // Newton cooling: T = 25 + (T_d - 25) e^{-t/tau}.
    EXPECT_NEAR(plant.block_degC(), 25.0 + (hot - 25.0) * std::exp(-t / kTau), 0.1);
    EXPECT_TRUE(board->mcu().pin("PB4").level());  // the firmware still drives the gate
    EXPECT_FALSE(heater.on());
    EXPECT_NEAR(heater.energy_J(), energy, 1e-9);  // no more energy delivered
    EXPECT_EQ(heater.fault(), "disconnected");
}

TEST(HeaterFault, StuckOnMosfetHeatsWithTheGateLow) {
    // pwm_heater with duty 0 keeps the gate low; stuck on at 10 s the block
    // follows the full-power step response from there.
    auto board = test::thermal_board(test::kSingleNodeBoard, "thermal_pwm_off");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    const Cycle at = board->mcu().cycles_from_seconds(10.0);
    board->part_as<Heater>("heater").inject(Heater::Fault::StuckOn, at);
    board->run_until_seconds(110.0);
    EXPECT_FALSE(board->mcu().pin("PB4").level());
    const double t = static_cast<double>(board->mcu().cycle() - at) / 16e6;
    EXPECT_NEAR(plant.block_degC(), 25.0 + kRise * (1.0 - std::exp(-t / kTau)), 0.1);
}

TEST(HeaterFault, StuckOnTripsMaxtempAndTheOverheatFinding) {
    // On RAMPS with the protection firmware: the MOSFET fails at 150 s while
    // holding 200 degC. The firmware turns the gate off, the block heats on:
    // MAXTEMP (275 degC) trips, and the plant reports passing 285 degC.
    auto board = test::ramps_board("thermal_runaway");
    board->part_as<Heater>("hotend_heater").inject(Heater::Fault::StuckOn, board->mcu().cycles_from_seconds(150.0));
    board->run_for_seconds(260.0);
    EXPECT_EQ(board->mcu().read_ram_u8("error"), 4) << "MAXTEMP";
    EXPECT_TRUE(board->part_as<Heater>("hotend_heater").on());
    bool overheat = false;
    for (const auto& f : board->findings()) overheat = overheat || (f.kind == ThermalPlant::kOverheat && f.source == "hotend");
    EXPECT_TRUE(overheat);
}

TEST(ThermalFault, StoppedFanRaisesTheSteadyState) {
    // Half duty (20 W) with the fan on: 25 + 20 / 0.097 = 231.19 degC; the fan
    // stops at 200 s: the loss falls to 0.068 W/K, 25 + 20 / 0.068 = 319.12 degC.
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: custom, heat_capacity: 2J/K, ambient_conductance: 0.068W/K, ambient_conductance_fan: 0.097W/K, sensor_time_constant: 0s}
  heater: {type: heater, preset: cartridge_40w_12v}
  fan: {type: fan, spin_time_constant: 0.5s}
nets:
  hotend_body: [hotend.body, heater.body, fan.body]
  gate: [mega.PB4, heater.gate]
  fan: [mega.PH6, fan.pwm]
)";
    auto board = test::thermal_board(yaml, "thermal_pwm_half_fan");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    auto& fan = board->part_as<Fan>("fan");
    fan.inject(Fan::Fault::Stopped, board->mcu().cycles_from_seconds(200.0));
    board->run_until_seconds(200.0);
    EXPECT_NEAR(plant.block_degC(), 231.19, 0.1);
    board->run_until_seconds(201.0);
    // Spinning down: speed e^{-1 s / 0.5 s} = 0.135 after one second.
    EXPECT_NEAR(fan.speed(), std::exp(-2.0), 0.01);
    EXPECT_TRUE(board->mcu().pin("PH6").level());  // still driven
    board->run_until_seconds(600.0);
    EXPECT_EQ(plant.fan_speed(), 0.0);
    EXPECT_NEAR(plant.block_degC(), 319.12, 0.1);
}

TEST(ThermalFault, UnknownFaultNamesAreRejected) {
    auto board = test::thermal_board(test::kSingleNodeBoard, "thermal_pwm_off");
    try {
        board->part("t0").inject_fault("melted", 0);
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("faults: none, open, shorted, detached"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace avrbench
