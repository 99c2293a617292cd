// The pin-level serial peer against another one: the same baud decodes every
// byte; 10 % off puts edges off the bit grid (the 8N1 budget is about 4.5 %,
// ATmega328P §20.8 Table 20-2) and is reported.
#include <gtest/gtest.h>

#include "boards/Board.hpp"
#include "parts/SerialPeer.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

std::vector<Finding> talk(const std::string& sender_baud, std::string& received) {
    const std::string text = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  sender: {type: serial_peer, baud: )" + sender_baud + R"(, send: "Az~", send_at: 1ms}
  listener: {type: serial_peer, baud: 9600}
nets:
  line: [sender.tx, listener.rx]
)";
    Board board(parse_board_text(text, "peers.yaml"), {{"uno", test::firmware("sleep_idle")}});
    board.run_for_seconds(0.01);  // 3 frames of 1.04 ms from 1 ms on
    received = board.part_as<SerialPeer>("listener").received();
    return board.findings();
}

TEST(SerialPeer, DecodesFramesAtItsBaud) {
    std::string received;
    EXPECT_TRUE(talk("9600", received).empty());
    EXPECT_EQ(received, "Az~");
}

TEST(SerialPeer, ReportsASenderTenPercentFast) {
    std::string received;
    const auto findings = talk("10560", received);
    ASSERT_FALSE(findings.empty());
    EXPECT_EQ(findings.front().kind, SerialPeer::kSerialFraming);
    EXPECT_EQ(findings.front().source, "listener");
}

}  // namespace
}  // namespace avrbench
