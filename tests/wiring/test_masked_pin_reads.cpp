// A firmware that reads a whole PINx byte but keeps only some bits at once
// (IN/LDS then ANDI, COM + ANDI, or SBRS) does not read the other pins: a
// floating one among them is no finding (firmware/boards/pin_masked_read).
// Prusa-Firmware's MMU2::WhereIsFilament reads PINK that way while the
// TMC2130 DIAG pins float before their pull-ups are on.
#include <gtest/gtest.h>

#include "boards/Board.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

// PB1 joins a knob contact that is open (released): nothing drives the net
// and the firmware never turns PB1's pull-up on, so it floats.
Board floating_pb1(const std::string& firmware) {
    const char* text = R"(
board: floating-pb1
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  knob: {type: rotary_knob}
nets:
  floating: [uno.PB1, knob.a]
)";
    return Board(parse_board_text(text, "floating.yaml"), {{"uno", test::firmware(firmware)}});
}

TEST(MaskedPinReads, AWholeByteMaskedToAnotherPinIsNoFloatingRead) {
    Board board = floating_pb1("pin_masked_read");
    board.run_for_seconds(0.001);
    ASSERT_EQ(board.mcu().read_ram_u8("done"), 1);
    EXPECT_TRUE(board.findings().empty());
}

TEST(MaskedPinReads, AWholeByteKeptReadsTheFloatingPin) {
    Board board = floating_pb1("pin_unmasked_read");
    board.run_for_seconds(0.001);
    ASSERT_EQ(board.mcu().read_ram_u8("done"), 1);
    ASSERT_EQ(board.findings().size(), 1u);
    EXPECT_EQ(std::string(board.findings()[0].kind.name()), "floating-input-read");
    EXPECT_EQ(board.findings()[0].source, "floating");
}

}  // namespace
}  // namespace avrbench
