// The rotary_knob part on the Einsy RAMBo, read by our own firmware
// (firmware/boards/knob_menu) as quadrature, 4 transitions a detent.
#include <gtest/gtest.h>

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "parts/RotaryKnob.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

TEST(RotaryKnob, TurnsDetentByDetentAtItsRate) {
    Board board(load_board_file("einsy-rambo"), {{"mega", test::firmware("knob_menu")}});
    board.run_for_seconds(0.1);
    auto& knob = dynamic_cast<RotaryKnob&>(board.part("knob"));
    knob.turn(3);
    // 10 detents/s, 4 transitions each: one transition every 25 ms, the k-th
    // 25k ms after the turn began; at 290 ms, 11 of the 12 are done.
    board.run_for_seconds(0.29);
    EXPECT_EQ(knob.position(), 11);
    board.run_for_seconds(0.11);
    EXPECT_EQ(knob.position(), 12);
    EXPECT_EQ(static_cast<std::int16_t>(board.mcu().read_ram_u16("transitions")), 12);
    EXPECT_EQ(static_cast<std::int16_t>(board.mcu().read_ram_u16("detents")), 3);
    knob.turn(-5);
    board.run_for_seconds(0.6);
    EXPECT_EQ(static_cast<std::int16_t>(board.mcu().read_ram_u16("detents")), -2);
    EXPECT_EQ(board.mcu().read_ram_u16("missed"), 0);
}

TEST(RotaryKnob, APressIsOneClick) {
    Board board(load_board_file("einsy-rambo"), {{"mega", test::firmware("knob_menu")}});
    board.run_for_seconds(0.1);
    auto& knob = dynamic_cast<RotaryKnob&>(board.part("knob"));
    knob.act("press", {});
    board.run_for_seconds(0.05);
    EXPECT_TRUE(knob.pressed());
    knob.act("release", {});
    board.run_for_seconds(0.05);
    EXPECT_EQ(board.mcu().read_ram_u16("clicks"), 1);
    EXPECT_THROW(knob.act("spin", {}), BadInput);
    EXPECT_THROW(knob.act("turn", {1.5}), BadInput);
}

}  // namespace
}  // namespace avrbench
