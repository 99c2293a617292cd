// A hall-effect endstop in place of the X limit switch of the UNO + CNC
// shield board (bench/boards/arduino-uno-cnc-shield-v3.yaml: PB1 with the
// MCU's pull-up, X at 250 steps/mm from 100 mm), driven by grbl_stepper,
// which stops a move and prints ALARM:1 when PB1 falls
// (firmware/boards/grbl_stepper/README.md).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "parts/HallEndstop.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"
#include "support/RunCommand.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

// The sensor 5 mm below the start, with the part's defaults: B0 = 1000 G,
// d0 = 3 mm, operate 250 G, A1324's 5 mV/G around 2.5 V.
std::string hall_board() {
    const auto path = test::scratch_dir("hall") / "hall.yaml";
    std::ofstream(path) << "board: hall-on-x\n"
                        << "extends: " << test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml") << "\n"
                        << "parts:\n"
                        << "  x_limit: {type: hall_endstop, position: 95mm}\n";
    return path.string();
}

std::unique_ptr<Bench> hall_bench() {
    auto bench = std::make_unique<Bench>(hall_board(), test::firmware("grbl_stepper"));
    // grbl_stepper greets with its own banner, not grbl's: a generic host.
    UartHostOptions host = default_host_options(bench->serial_port(""));
    host.family = FirmwareFamily::Generic;
    bench->host("", host);
    return bench;
}

TEST(HallEndstop, TheLinearOutputFollowsTheMagnetsDistance) {
    auto bench = hall_bench();
    auto& hall = bench->board().part_as<HallEndstop>("x_limit");
    std::size_t port = 0;
    ASSERT_NE(hall.find_port("analog", &port), nullptr);
    // d = 100 - 95 = 5 mm: 1 + (5/3)^2 = 34/9 = 3.777778, its 1.5th power
    // 3.777778 x 1.943651 = 7.342681, B = 1000 / 7.342681 = 136.1901 G;
    // V = 2.5 V + 5 mV/G x 136.1901 G = 3.180950 V.
    EXPECT_NEAR(hall.field_G(), 136.1901, 1e-3);
    EXPECT_NEAR(hall.analog_volts(port, 0), 3.180950, 1e-5);
}

TEST(HallEndstop, TripsAtTheStepThatBringsTheFieldToTheOperatePoint) {
    auto bench = hall_bench();
    test::PinLog step{bench->mcu(), "PD2"}, limit{bench->mcu(), "PB1"};
    bench->host().add_lines("X-2500\n");  // toward the sensor, 10 mm
    bench->run_until_idle(10.0);
    // B(d) = 250 G at d = 3 mm x sqrt(4^(2/3) - 1) = 3.6984 mm, carriage at
    // 98.6984 mm: step 325 (98.700 mm) gives 249.81 G, step 326 (98.696 mm)
    // 250.30 G. The output pulls PB1 low at that step's STEP edge.
    ASSERT_GE(step.rises().size(), 326u);
    ASSERT_FALSE(limit.falls().empty());
    EXPECT_EQ(limit.falls().front(), step.rises()[325]);
    auto& hall = bench->board().part_as<HallEndstop>("x_limit");
    EXPECT_EQ(hall.trips(), 1u);
    EXPECT_TRUE(hall.switched_on());
    // The firmware saw it: the move stopped with ALARM:1, short of the 10 mm.
    EXPECT_NE(bench->host().tail(10).find("ALARM:1"), std::string::npos) << bench->host().tail(10);
    EXPECT_LT(step.rises().size(), 2500u);
}

}  // namespace
}  // namespace avrbench
