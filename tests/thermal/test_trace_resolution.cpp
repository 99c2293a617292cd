// `trace_resolution` (every part type's parameter): a part's real signal is
// recorded only when it changed by at least that much since the last value
// recorded; the part's own value stays exact. The plant of
// ThermalPlant.SteadyStateIsProportionalToDuty (2 J/K, 0.068 W/K, 10 W mean
// from firmware/thermal's quarter-duty PWM at 61 Hz) rises from 25 to
// 25 + 10 / 0.068 = 172.06 degC (tau 29.4 s, 400 s = 13.6 tau), with PWM
// ripple on the way (0.06 K peak to peak at the end): rounding would record
// every swing across a boundary, a deadband of 1 K records each degree once.
#include <gtest/gtest.h>

#include <cmath>

#include "parts/ThermalPlant.hpp"
#include "thermal/ThermalTestSupport.hpp"

namespace avrbench {
namespace {

std::vector<double> block_trace(const std::string& resolution, double* exact_end) {
    auto board = test::thermal_board(R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: custom, heat_capacity: 2J/K, ambient_conductance: 0.068W/K, sensor_time_constant: 0s, sample_interval: 1ms)" +
                                         (resolution.empty() ? "" : ", trace_resolution: " + resolution) + R"(}
  heater: {type: heater, preset: cartridge_40w_12v}
nets:
  hotend_body: [hotend.body, heater.body]
  gate: [mega.PB4, heater.gate]
)",
                                     "thermal_pwm_quarter");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    const std::size_t block = *plant.signal_index("block_degC");
    std::vector<double> told;
    plant.watch_signals([&](std::size_t signal, Cycle, double value) {
        if (signal == block) told.push_back(value);
    });
    board->run_for_seconds(400);
    *exact_end = plant.block_degC();
    return told;
}

TEST(TraceResolution, AWholeDegreeRecordsEachDegreeOfTheRiseOnce) {
    double exact = 0;
    const std::vector<double> told = block_trace("1", &exact);
    // Each recorded value at least 1 K above the one before, and at most 1 K
    // plus one sample's change: 40 W / 2 J/K over 1 ms = 0.02 K. So the
    // 147.06 K of the rise holds 1 + 147.06 / 1.02 = 145.2 .. 1 + 147.06 = 148.06
    // values: 145 to 148.
    ASSERT_GE(told.size(), 145u);
    ASSERT_LE(told.size(), 148u);
    EXPECT_DOUBLE_EQ(told.front(), 25.0);
    for (std::size_t i = 1; i < told.size(); ++i) {
        EXPECT_GE(told[i] - told[i - 1], 1.0) << i;
        EXPECT_LE(told[i] - told[i - 1], 1.02) << i;
    }
    EXPECT_NEAR(exact, 172.06, 0.1);  // the part's own value: the latest, not the last recorded
    EXPECT_LT(exact - told.back(), 1.0);
}

TEST(TraceResolution, WithoutItEverySampleIsRecorded) {
    double exact = 0;
    // One value per 1 ms sample_interval: 400 000 in 400 s (give or take the first).
    const std::vector<double> told = block_trace("", &exact);
    EXPECT_NEAR(static_cast<double>(told.size()), 400000.0, 2.0);
    EXPECT_NEAR(told.back(), exact, 0.02);  // the last sample, at most 1 ms old
}

}  // namespace
}  // namespace avrbench
