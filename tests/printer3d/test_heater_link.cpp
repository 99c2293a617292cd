// Seed 001's heater MCU (firmware/printer3d_heater, an ATmega32 TWI slave)
// with its hot end, and a TWI master in the interpolator's place
// (firmware/printer3d_heater_probe_60: setpoint 60 degC, then a status read
// every 500 ms), on bench/boards/printer3d-heater-seed001.yaml. Expected
// values: the digest's §10.4 and §10.7 and the link's format (the heater
// firmware's header). Each test runs under ctest's 300 s wall-clock limit.
#include <gtest/gtest.h>

#include <cmath>

#include "boards/Board.hpp"
#include "parts/ThermalPlant.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"

namespace avrbench {
namespace {

TEST(Printer3dHeater, TheSetpointGoesOverTwiAndTheHotEndHoldsIt) {
    Board board(load_board_file(test::source_path("bench/boards/printer3d-heater-seed001.yaml")),
                {{"host", test::firmware("printer3d_heater_probe_60")}, {"heater", test::firmware("printer3d_heater")}});
    Mcu& host = board.mcu("host");
    Mcu& heater = board.mcu("heater");
    auto& plant = board.part_as<ThermalPlant>("hotend");
    test::PinLog gate(heater, "PD7");
    double t = 0;
    while (heater.read_ram_u8("temp_ok") == 0 && t < 30) board.run_until_seconds(t += 0.25);
    ASSERT_EQ(heater.read_ram_u8("temp_ok"), 1) << "not within 5 degC of 60 by 30 s";
    EXPECT_EQ(heater.read_ram_u16("setpoint_c"), 60u);  // written over TWI
    board.run_for_seconds(3);
    // TEMP_OK (PD6) follows |setpoint - T| < 5 on the heater's own reading (§10.7).
    const double own_c = static_cast<std::int16_t>(heater.read_ram_u16("temp_x10")) / 10.0;
    EXPECT_EQ(heater.pin("PD6").level(), std::abs(60.0 - own_c) < 5.0) << own_c;
    // The thesis' gains (200, 1, 500 per degC here; about 236, 1.2, 590 per
    // degC in its 8-bit counts at 190 degC) keep the heater on full until the
    // last 2 degC, and the block outruns its sensor: the hot end overshoots
    // 60 degC, and above the setpoint the gate is at its 1/256 minimum.
    EXPECT_LT(plant.block_degC(), 75.0);
    if (own_c > 61.0) {
        EXPECT_EQ(heater.read_ram_u8("duty"), 0u);
    }
    // The host reads what the heater measures (0.1 degC over TWI): the
    // thermistor's view of the sensor node, within the 10-bit conversion's
    // resolution there (~1.5 codes per degC at 60 degC with the 891.7 ohm leg).
    EXPECT_GT(host.read_ram_u16("reads"), 10u);
    EXPECT_EQ(host.read_ram_u16("errors"), 0u);
    EXPECT_EQ(host.read_ram_u16("seen_setpoint"), 60u);
    const double seen_c = static_cast<std::int16_t>(host.read_ram_u16("seen_temp_x10")) / 10.0;
    EXPECT_NEAR(seen_c, plant.sensor_degC(), 1.5);
    // Holding, the PID modulates the gate: Timer2 fast PWM at clk/128, a
    // period of 128 * 256 = 32768 cycles (2.048 ms, 488.28 Hz; §10.4).
    const auto periods = test::PinLog::differences(gate.rises());
    ASSERT_GE(periods.size(), 2u);
    bool found = false;
    for (Cycle p : periods) found = found || p == 32768u;
    EXPECT_TRUE(found);
    for (Cycle p : periods) EXPECT_EQ(p % 32768u, 0u);  // whole PWM periods (cycles at 0 % skip edges)
    EXPECT_TRUE(board.findings().empty());
}

}  // namespace
}  // namespace avrbench
