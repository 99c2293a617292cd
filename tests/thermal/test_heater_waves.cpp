// A heater whose gate is a hardware PWM the timer hands out as a periodic
// wave (periph/timer/PeriodicOutput.hpp, parts/Heater.hpp): the on-time is the one the
// gate's edges give, the plant's temperatures stay within the bound the
// averaging allows, and skipping idle loops changes nothing.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "parts/Heater.hpp"
#include "parts/ThermalPlant.hpp"
#include "thermal/ThermalTestSupport.hpp"

namespace avrbench {
namespace {

struct HeaterRun {
    Cycle cycle = 0;
    Cycle on_cycles = 0;
    double block_degC = 0;
    double sensor_degC = 0;
    std::vector<std::uint8_t> data;
    bool followed_first = false, followed_second = false;
};

// firmware/boards/ramps_teacup on RAMPS 1.4: the hot end heater on D10 =
// OC2A, Timer2 fast PWM at clk/64 (a period of 256 * 64 = 16384 cycles,
// 1.024 ms). `waves`: the gate may be handed out as a wave; otherwise every
// edge goes through the net.
HeaterRun run_heater(bool waves, bool skip_idle_loops, bool faults = false) {
    auto board = test::ramps_board("ramps_teacup");
    Mcu& mcu = board->mcu("mega");
    mcu.set_skip_idle_loops(skip_idle_loops);
    if (!waves) mcu.set_periodic_output_sink(mcu.pin("PB4"), nullptr);
    auto& heater = board->part_as<Heater>("hotend_heater");
    auto& plant = board->part_as<ThermalPlant>("hotend");
    if (faults) {
        // The MOSFET fails short at 0.6 s and is repaired at 0.8 s; the heater
        // circuit opens at 1.5 s.
        const double f = mcu.frequency_hz();
        heater.inject(Heater::Fault::StuckOn, static_cast<Cycle>(0.6 * f));
        heater.inject(Heater::Fault::None, static_cast<Cycle>(0.8 * f));
        heater.inject(Heater::Fault::Disconnected, static_cast<Cycle>(1.5 * f));
    }
    board->run_for_seconds(0.01);
    mcu.uart(0).send("M42 P10 S64\n");
    board->run_for_seconds(1.0);
    HeaterRun r;
    r.followed_first = heater.follows_wave();
    mcu.uart(0).send("M42 P10 S200\n");  // OCR2A written: the wave ends, another begins
    board->run_for_seconds(1.0);
    r.followed_second = heater.follows_wave();
    mcu.settle_periodic_outputs();
    r.cycle = mcu.cycle();
    r.on_cycles = heater.on_cycles();
    r.block_degC = plant.block_degC();
    r.sensor_degC = plant.sensor_degC();
    r.data = mcu.data_memory();
    return r;
}

TEST(HeaterWaves, OnTimeIsTheGatesAndTemperaturesStayWithinTheAveragingBound) {
    const HeaterRun edges = run_heater(false, true), waves = run_heater(true, true);
    EXPECT_FALSE(edges.followed_first);
    EXPECT_TRUE(waves.followed_first);
    EXPECT_TRUE(waves.followed_second);
    ASSERT_EQ(edges.cycle, waves.cycle);
    // Counted from the wave exactly as from the edges.
    EXPECT_EQ(edges.on_cycles, waves.on_cycles);
    // By hand (2560 §20.7.3): high for OCR2A + 1 timer clocks of 256, so
    // 65/256 for about 1 s, then 201/256 for about 1 s: 16e6 * (65 + 201) / 256
    // = 16.6 M cycles, less the serial line's and the loop's delay in taking
    // each command (a few ms).
    EXPECT_NEAR(static_cast<double>(waves.on_cycles), 16e6 * (65.0 + 201.0) / 256.0, 16e6 * 0.01);
    // Mean power instead of each edge: the block's ripple is at most
    // P * T / C = 40 W * 1.024 ms / 16.7 J/K = 2.5 mK (Heater.hpp).
    EXPECT_NEAR(edges.block_degC, waves.block_degC, 0.005);
    EXPECT_NEAR(edges.sensor_degC, waves.sensor_degC, 0.005);
    EXPECT_GT(waves.block_degC, 25.5);  // it did heat: ~24 J into 16.7 J/K
}

TEST(HeaterWaves, FaultsTakeEffectAtTheirCycleWhetherOrNotTheGateIsAWave) {
    const HeaterRun edges = run_heater(false, true, true), waves = run_heater(true, true, true);
    EXPECT_TRUE(waves.followed_first);    // repaired at 0.8 s: following again at 1.01 s
    EXPECT_FALSE(waves.followed_second);  // disconnected from 1.5 s on
    EXPECT_EQ(edges.on_cycles, waves.on_cycles);
    // By hand: 65/256 from the command (~0.01 s) to 0.6 s, on for 0.2 s,
    // 65/256 to ~1.01 s, 201/256 to 1.5 s, then off: 16e6 * (0.59 * 65/256 +
    // 0.2 + 0.21 * 65/256 + 0.49 * 201/256) = 13.6 M cycles.
    EXPECT_NEAR(static_cast<double>(waves.on_cycles), 16e6 * (0.59 * 65.0 / 256 + 0.2 + 0.21 * 65.0 / 256 + 0.49 * 201.0 / 256),
                16e6 * 0.01);
    EXPECT_NEAR(edges.block_degC, waves.block_degC, 0.005);
}

TEST(HeaterWaves, SkippingIdleLoopsChangesNothing) {
    const HeaterRun plain = run_heater(true, false), skipping = run_heater(true, true);
    EXPECT_TRUE(skipping.followed_first);
    EXPECT_EQ(plain.cycle, skipping.cycle);
    EXPECT_EQ(plain.on_cycles, skipping.on_cycles);
    EXPECT_EQ(plain.block_degC, skipping.block_degC);  // bit for bit
    EXPECT_EQ(plain.sensor_degC, skipping.sensor_degC);
    EXPECT_TRUE(plain.data == skipping.data) << "registers, I/O or RAM differ";
}

}  // namespace
}  // namespace avrbench
