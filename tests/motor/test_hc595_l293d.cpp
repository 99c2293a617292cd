// The 74HC595 and L293D parts, driven pin by pin from the test (the MCU runs
// sleep_idle, which leaves PORTC and PORTD alone), and the 74HC595 as the
// Adafruit Motor Shield v1 uses it.
#include <gtest/gtest.h>

#include <vector>

#include "boards/Board.hpp"
#include "parts/L293D.hpp"
#include "parts/ShiftRegister595.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

const char* const kBench = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  sr: {type: shift_register_595}
  ic: {type: l293d, supply: 12V}
nets:
  ser: [uno.PD2, sr.ser]
  srclk: [uno.PD3, sr.srclk]
  rclk: [uno.PD4, sr.rclk]
  oe: [uno.PD5, sr.oe]
  srclr: [uno.PD6, sr.srclr]
  q0: [sr.q0, uno.PC0]
  q1: [sr.q1, uno.PC1]
  q6: [sr.q6, uno.PC2]
  q7: [sr.q7, uno.PC3]
  q7s: [sr.q7s, uno.PC4]
  en12: [uno.PB0, ic.en12]
  in1: [uno.PB1, ic.in1]
  in2: [uno.PB2, ic.in2]
  in3: [uno.PB3, ic.in3]
  in4: [uno.PB4, ic.in4]
)";

struct PinBench {
    Board board{parse_board_text(kBench, "pin-bench.yaml"), {{"uno", test::firmware("sleep_idle")}}};
    Mcu& uno = board.mcu("uno");
    ShiftRegister595& sr = board.part_as<ShiftRegister595>("sr");
    L293D& ic = board.part_as<L293D>("ic");
    PinBench() {
        for (const char* p : {"PD2", "PD3", "PD4", "PD5", "PD6", "PB0", "PB1", "PB2", "PB3", "PB4"}) {
            board.drive_pin(std::string("uno.") + p, false);
        }
        board.drive_pin("uno.PD6", true);  // SRCLR inactive
        board.run_for_seconds(0.001);
    }
    void set(const char* pin, bool level) {
        board.drive_pin(std::string("uno.") + pin, level);
        board.run_for_seconds(1e-6);
    }
    // latch_tx(): MSB first, then a rising RCLK (seed 003 digest §2.4).
    void shift_out(std::uint8_t byte) {
        set("PD4", false);
        for (int i = 0; i < 8; ++i) {
            set("PD3", false);
            set("PD2", (byte & (0x80 >> i)) != 0);
            set("PD3", true);
        }
        set("PD4", true);
    }
};

TEST(Hc595, ShiftsMsbFirstAndLatchesOnRclk) {
    PinBench b;
    b.shift_out(0xC1);  // bit n lands on Qn: Q7 Q6 = 1, Q0 = 1
    EXPECT_EQ(b.sr.storage_register(), 0xC1);
    EXPECT_TRUE(b.uno.pin("PC0").level());
    EXPECT_FALSE(b.uno.pin("PC1").level());
    EXPECT_TRUE(b.uno.pin("PC2").level());
    EXPECT_TRUE(b.uno.pin("PC3").level());
    EXPECT_TRUE(b.uno.pin("PC4").level());  // Q7S = stage 7
    // Shifting alone changes no output until RCLK rises.
    b.set("PD4", false);
    b.set("PD2", false);
    b.set("PD3", false);
    b.set("PD3", true);
    EXPECT_EQ(b.sr.shift_register(), 0x82);
    EXPECT_EQ(b.sr.storage_register(), 0xC1);
    EXPECT_TRUE(b.uno.pin("PC0").level());
}

TEST(Hc595, OutputsAreHighImpedanceWhileOeIsHigh) {
    PinBench b;
    b.shift_out(0x01);
    ASSERT_TRUE(b.uno.pin("PC0").level());
    b.set("PD5", true);
    EXPECT_FALSE(b.sr.outputs_enabled());
    EXPECT_FALSE(b.uno.pin("PC0").level());  // released: the input reads 0 without a pull-up
    b.set("PD5", false);
    EXPECT_TRUE(b.uno.pin("PC0").level());
}

TEST(Hc595, SrclrClearsTheShiftRegisterNotTheOutputs) {
    PinBench b;
    b.shift_out(0xFF);
    b.set("PD6", false);
    EXPECT_EQ(b.sr.shift_register(), 0);
    EXPECT_EQ(b.sr.storage_register(), 0xFF);
    b.set("PD6", true);
    b.set("PD4", false);
    b.set("PD4", true);
    EXPECT_EQ(b.sr.storage_register(), 0);
}

TEST(Hc595, MotorShieldLatchesAfMotorsDoubleSequence) {
    // Seed 003 digest §7.1: stepper 2, DOUBLE FORWARD from a fresh object
    // latches 0x21 (A+B+), 0x81 (B+A-), 0xC0 (A-B-), 0x60 (B-A+), repeating,
    // after the initial 0x00 of MC.enable().
    Board board(load_board_file(test::source_path("bench/boards/arduino-uno-motor-shield-v1.yaml")),
                {{"uno", test::firmware("motor_avr446")}});
    auto& sr = board.part_as<ShiftRegister595>("latch");
    std::vector<int> bytes;
    const std::size_t outputs = 1;  // signals: shift, outputs, outputs_enabled
    sr.watch_signals([&](std::size_t signal, Cycle, double value) {
        if (signal == outputs) bytes.push_back(static_cast<int>(value));
    });
    board.run_until_seconds(0.12);  // c0 = 16.9 ms, then faster: > 6 steps
    ASSERT_GE(bytes.size(), 6u);
    const std::vector<int> expected = {0x00, 0x21, 0x81, 0xC0, 0x60, 0x21};
    EXPECT_EQ(std::vector<int>(bytes.begin(), bytes.begin() + 6), expected);
}

TEST(L293d, FollowsTheDatasheetTruthTable) {
    // SLRS008C function table: EN = H: Y = A; EN = L: Y = Z.
    PinBench b;
    b.set("PB0", true);
    b.set("PB1", true);
    EXPECT_EQ(b.ic.output(1), L293D::Output::High);
    EXPECT_EQ(b.ic.output(2), L293D::Output::Low);
    b.set("PB0", false);
    EXPECT_EQ(b.ic.output(1), L293D::Output::Off);
    EXPECT_EQ(b.ic.output(2), L293D::Output::Off);
    // 3,4EN has no net: the board's default ties it high.
    b.set("PB3", true);
    EXPECT_EQ(b.ic.output(3), L293D::Output::High);
    EXPECT_EQ(b.ic.output(4), L293D::Output::Low);
}

TEST(L293d, WindingVoltagesUseTheDatasheetDrops) {
    // 12 V supply; V_OH = 12 - 1.4 V, V_OL = 1.2 V, clamps 1.3 V (typical).
    PinBench b;
    b.set("PB0", true);
    b.set("PB1", true);  // 1Y high, 2Y low
    WindingDrive d = b.ic.winding(1, 2);
    EXPECT_DOUBLE_EQ(d.v_pos, 12 - 1.4 - 1.2);  // forward: source + sink
    EXPECT_DOUBLE_EQ(d.v_neg, 12 + 1.3 + 1.3);  // reverse current: both clamps into the supply
    EXPECT_EQ(d.polarity, 1);
    b.set("PB1", false);  // both low: brake through the low side
    d = b.ic.winding(1, 2);
    EXPECT_DOUBLE_EQ(d.v_pos, -1.3 - 1.2);
    EXPECT_DOUBLE_EQ(d.v_neg, 1.2 + 1.3);
    EXPECT_EQ(d.polarity, 0);
    b.set("PB2", true);  // 1Y low, 2Y high: reverse
    d = b.ic.winding(1, 2);
    EXPECT_DOUBLE_EQ(d.v_pos, -(12 + 1.3 + 1.3));
    EXPECT_DOUBLE_EQ(d.v_neg, -(12 - 1.4 - 1.2));
    EXPECT_EQ(d.polarity, -1);
    b.set("PB0", false);  // disabled: only the clamp diodes conduct
    d = b.ic.winding(1, 2);
    EXPECT_DOUBLE_EQ(d.v_pos, -(12 + 2 * 1.3));
    EXPECT_DOUBLE_EQ(d.v_neg, 12 + 2 * 1.3);
    EXPECT_EQ(d.polarity, 0);
}

}  // namespace
}  // namespace avrbench
