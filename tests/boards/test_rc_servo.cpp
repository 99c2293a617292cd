// The rc_servo part (parts/RcServo.hpp) on the pulses of firmware/servo_sweep
// (Timer1 fast PWM, 20 ms frames, widths exact to the 0.5 us tick). The board
// gives a linear table 0:1000,180:2000 (0.18 deg/us) and 300 deg/s, so every
// expected angle below is worked out by hand.
#include <gtest/gtest.h>

#include <vector>

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "parts/RcServo.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

struct Change {
    Cycle cycle;
    double value;
};

TEST(RcServo, FollowsPulseWidthsAtItsSlewRateAndReportsOutOfRangePulses) {
    const std::string text = R"(mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  pen: {type: rc_servo, calibration: "0:1000,180:2000", slew_deg_per_s: 300, initial_angle: 90deg}
nets:
  d9: [uno.PB1, pen.signal]
)";
    Board board(parse_board_text(text, "servo.yaml"), {{"uno", test::firmware("servo_sweep")}});
    auto& servo = board.part_as<RcServo>("pen");
    std::vector<Change> targets, angles;
    servo.watch_signals([&](std::size_t signal, Cycle cycle, double value) {
        if (servo.signals()[signal].name == "target_deg") targets.push_back({cycle, value});
        if (servo.signals()[signal].name == "angle_deg") angles.push_back({cycle, value});
    });

    board.run_until_seconds(0.45);
    // 1500 us = 3000 ticks of 0.5 us -> 90 deg, where it started: no motion.
    EXPECT_DOUBLE_EQ(servo.last_pulse_us(), 1500.0);
    EXPECT_DOUBLE_EQ(servo.angle_deg(), 90.0);
    EXPECT_TRUE(targets.empty());
    // One pulse per 20 ms frame: 22 whole frames in 0.45 s.
    EXPECT_GE(servo.pulses(), 22u);
    EXPECT_LE(servo.pulses(), 23u);

    board.run_until_seconds(2.5);
    // Targets: 180 (2000 us), 0 (1000 us), 180 (3000 us clamped), 90 (1500 us).
    ASSERT_EQ(targets.size(), 4u);
    EXPECT_DOUBLE_EQ(targets[0].value, 180.0);
    EXPECT_DOUBLE_EQ(targets[1].value, 0.0);
    EXPECT_DOUBLE_EQ(targets[2].value, 180.0);
    EXPECT_DOUBLE_EQ(targets[3].value, 90.0);
    // The firmware changes OCR1A every 0.5 s; the pulses follow at frame
    // boundaries, so the commands are 25 frames (8 000 000 cycles) apart,
    // then 10 (3 200 000), each moved by the change of width, since a command
    // takes effect at the end of its pulse (16 cycles per us):
    // 2000 -> 1000 us: -16 000; 1000 -> 3000: +32 000; 3000 -> 1500: -24 000.
    EXPECT_EQ(targets[1].cycle - targets[0].cycle, 8'000'000u - 16'000u);
    EXPECT_EQ(targets[2].cycle - targets[1].cycle, 8'000'000u + 32'000u);
    EXPECT_EQ(targets[3].cycle - targets[2].cycle, 3'200'000u - 24'000u);

    // 90 -> 180 at 300 deg/s: 0.3 s, so it arrives 4 800 000 cycles after the
    // command, and is at 90 + 300 * 0.1 = 120 deg 0.1 s in (the pulse ending
    // 5 frames later publishes it).
    bool arrived = false, at_120 = false;
    for (const Change& a : angles) {
        if (a.cycle == targets[0].cycle + 4'800'000u) arrived = a.value == 180.0;
        if (a.cycle == targets[0].cycle + 1'600'000u) at_120 = std::abs(a.value - 120.0) < 1e-9;
    }
    EXPECT_TRUE(arrived);
    EXPECT_TRUE(at_120);
    // 180 -> 0 takes 0.6 s, but 8 032 000 cycles (0.502 s) later the 3000 us
    // command turns it round at 180 - 300 * 0.502 = 29.4 deg; towards 180
    // for 3 176 000 cycles (0.1985 s): 29.4 + 59.55 = 88.95 deg when 1500 us
    // (90 deg) arrives, which it reaches 1.05 / 300 s later.
    double at_third = -1, at_fourth = -1;
    for (const Change& a : angles) {
        if (a.cycle == targets[2].cycle) at_third = a.value;
        if (a.cycle == targets[3].cycle) at_fourth = a.value;
    }
    EXPECT_NEAR(at_third, 29.4, 1e-9);
    EXPECT_NEAR(at_fourth, 88.95, 1e-9);
    EXPECT_DOUBLE_EQ(servo.angle_deg(), 90.0);

    // The 3000 us pulses: one finding for the whole spell of them.
    int out_of_range = 0;
    for (const Finding& f : board.findings()) {
        if (f.kind != RcServo::kServoPulseOutOfRange) continue;
        ++out_of_range;
        EXPECT_NE(f.detail.find("pulse of 3000.0 us is outside the calibrated 1000..2000 us"), std::string::npos)
            << f.detail;
        EXPECT_EQ(f.cycle, targets[2].cycle);
    }
    EXPECT_EQ(out_of_range, 1);
}

// A pulse longer than the servo accepts (max_pulse 2500 us here; servo_sweep
// sends 2000 us from about 0.5 s, 1000 us 25 frames later, 3000 us 25 frames
// after that, 1500 us 10 frames later: see the test above) is ignored - at
// 1.65 s the horn is at 0 deg, where the 1000 us pulses sent it (180 deg at
// 300 deg/s: 0.6 s, done by 1.6 s) - and reported once for the spell.
TEST(RcServo, PulsesOutsideWhatTheServoAcceptsAreIgnoredAndReported) {
    const std::string text = R"(mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  pen: {type: rc_servo, calibration: "0:1000,180:2000", slew_deg_per_s: 300, initial_angle: 90deg, max_pulse: 2500us}
nets:
  d9: [uno.PB1, pen.signal]
)";
    Board board(parse_board_text(text, "servo.yaml"), {{"uno", test::firmware("servo_sweep")}});
    auto& servo = board.part_as<RcServo>("pen");
    board.run_until_seconds(1.65);
    EXPECT_DOUBLE_EQ(servo.angle_deg(), 0.0) << "still at the 1000 us command";
    EXPECT_DOUBLE_EQ(servo.last_pulse_us(), 1000.0) << "the 3000 us pulses are not taken";
    int reported = 0;
    for (const Finding& f : board.findings()) {
        if (f.kind != RcServo::kServoPulseOutOfRange) continue;
        ++reported;
        EXPECT_NE(f.detail.find("pulse of 3000.0 us is outside the 400..2500 us the servo accepts; ignored"), std::string::npos)
            << f.detail;
    }
    EXPECT_EQ(reported, 1);
}

TEST(RcServo, CalibrationTableInterpolatesLinearlyBetweenItsPoints) {
    // [T4] Table 4.1, servo 1: 0:641, 45:1032, 90:1474, 135:1902, 180:2305 us.
    const std::string text = R"(mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  s1: {type: rc_servo, calibration: "0:641,45:1032,90:1474,135:1902,180:2305", slew_deg_per_s: 285}
)";
    Board board(parse_board_text(text, "servo.yaml"), {{"uno", test::firmware("servo_sweep")}});
    const auto& s1 = board.part_as<RcServo>("s1");
    EXPECT_DOUBLE_EQ(s1.angle_for_pulse_us(1474), 90.0);
    // Half way from 1032 to 1474 us (221 of 442): 45 + 22.5 deg.
    EXPECT_DOUBLE_EQ(s1.angle_for_pulse_us(1253), 67.5);
    EXPECT_DOUBLE_EQ(s1.angle_for_pulse_us(500), 0.0);    // clamped below
    EXPECT_DOUBLE_EQ(s1.angle_for_pulse_us(2500), 180.0);  // and above
}

TEST(RcServo, ATableThatDoesNotAscendIsAnError) {
    const std::string text = R"(mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  s: {type: rc_servo, calibration: "0:1000,90:900"}
)";
    try {
        Board board(parse_board_text(text, "bad-servo.yaml"), {{"uno", test::firmware("servo_sweep")}});
        FAIL() << "expected BadInput";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("bad-servo.yaml:4: part 's': calibration: '90:900' does not ascend"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace avrbench
