// Our RAMPS 1.4 temperature firmwares on the RAMPS board file: PID holding
// 200 degC (firmware/thermal/pid_heater) and the Marlin-style protection
// (firmware/thermal/runaway_guard) tripping when the thermistor falls out.
#include <gtest/gtest.h>

#include <cmath>

#include "parts/Heater.hpp"
#include "parts/ThermalPlant.hpp"
#include "parts/Thermistor.hpp"
#include "thermal/ThermalTestSupport.hpp"

namespace avrbench {
namespace {

TEST(PidHeater, FirmwareSeesAmbientAtStartAndTheTargetAfterHeating) {
    auto board = test::ramps_board("thermal_pid");
    Mcu& mega = board->mcu();
    board->run_for_seconds(0.15);  // the first reading is at 0 s, the second at 0.1 s
    ASSERT_GE(mega.read_ram_u16("samples"), 1);
    // 25 degC ambient (the e3d_v6 preset's), read through the EPCOS curve:
    // code 978 -> R = 4700 * 978 / 46 = 99 926 ohm -> 25.02 degC.
    EXPECT_NEAR(test::read_i16(mega, "temp_x10"), 250, 3);
    EXPECT_EQ(mega.read_ram_u8("heater_duty"), 255);  // far below the target: full power
    board->run_for_seconds(200);
    EXPECT_NEAR(test::read_i16(mega, "temp_x10"), 2000, 20);
}

TEST(PidHeater, HoldsTwoHundredWithinTwoDegreesAfterSettling) {
    auto board = test::ramps_board("thermal_pid");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    // Heating at 40 W from 25 degC reaches 195 degC after about 86 s
    // (-tau ln(1 - 170/588.2), tau = 245.6 s); settled well before 150 s.
    board->run_for_seconds(150);
    double worst_block = 0, worst_sensor = 0;
    for (int i = 0; i < 100; ++i) {
        board->run_for_seconds(1.0);
        worst_block = std::max(worst_block, std::abs(plant.block_degC() - 200.0));
        worst_sensor = std::max(worst_sensor, std::abs(plant.sensor_degC() - 200.0));
    }
    EXPECT_LE(worst_sensor, 2.0);
    EXPECT_LE(worst_block, 2.0);
    // Holding 200 degC takes 0.068 W/K * 175 K = 11.9 W of the 40 W: duty ~0.30.
    auto& heater = board->part_as<Heater>("hotend_heater");
    const Cycle on0 = heater.on_cycles(), c0 = board->mcu().cycle();
    board->run_for_seconds(20.0);
    const double duty = static_cast<double>(heater.on_cycles() - on0) / static_cast<double>(board->mcu().cycle() - c0);
    EXPECT_NEAR(duty, 0.068 * 175.0 / 40.0, 0.03);
}

TEST(RunawayGuard, HoldsTheTargetWithoutTripping) {
    auto board = test::ramps_board("thermal_runaway");
    board->run_for_seconds(200);
    EXPECT_EQ(board->mcu().read_ram_u8("error"), 0);
    EXPECT_NEAR(test::read_i16(board->mcu(), "temp_x10"), 2000, 20);
}

TEST(RunawayGuard, TripsWhenTheThermistorIsDetachedAtTheTarget) {
    auto board = test::ramps_board("thermal_runaway");
    auto& thermistor = board->part_as<Thermistor>("hotend_thermistor");
    auto& heater = board->part_as<Heater>("hotend_heater");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    board->run_for_seconds(150);
    ASSERT_EQ(board->mcu().read_ram_u8("error"), 0);
    thermistor.inject(Thermistor::Fault::Detached, board->mcu().cycles_from_seconds(150.0));
    // The bead cools to ambient with tau = 4.5 s: below 196 degC within a
    // second; the firmware heats at full power meanwhile (the block rises), and
    // after THERMAL_PROTECTION_PERIOD 40 s below target - 4 degC it trips.
    board->run_for_seconds(30);
    EXPECT_EQ(board->mcu().read_ram_u8("error"), 0);
    EXPECT_GT(plant.block_degC(), 205.0);  // heated blind
    EXPECT_LT(plant.sensor_degC(), 30.0);
    board->run_for_seconds(15);
    EXPECT_EQ(board->mcu().read_ram_u8("error"), 2) << "THERMAL_RUNAWAY";
    const unsigned at = board->mcu().read_ram_u16("error_at_s");
    EXPECT_GE(at, 190u);
    EXPECT_LE(at, 193u);
    EXPECT_FALSE(heater.on());
    const double peak = plant.block_degC();
    board->run_for_seconds(20);
    EXPECT_LT(plant.block_degC(), peak);  // cooling: the heater stays off
    EXPECT_FALSE(heater.on());
}

TEST(RunawayGuard, TripsWhenTheThermistorIsDetachedWhileHeating) {
    auto board = test::ramps_board("thermal_runaway");
    board->part_as<Thermistor>("hotend_thermistor").inject(Thermistor::Fault::Detached,
                                                           board->mcu().cycles_from_seconds(5.0));
    // The watch armed at 0 s expects 25 + 2 degC by 20 s. The bead, detached at
    // 5 s (about 29 degC then), is back to 25 + 4 e^{-15/4.5} = 25.1 degC by 20 s:
    // heating failed, error 1.
    board->run_for_seconds(21);
    EXPECT_EQ(board->mcu().read_ram_u8("error"), 1) << "HEATING_FAILED";
    EXPECT_FALSE(board->part_as<Heater>("hotend_heater").on());
}

}  // namespace
}  // namespace avrbench
