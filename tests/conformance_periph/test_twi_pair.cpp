// Two AVRs on one I2C bus (firmware/conformance/peripherals/twi_pair): the
// master's and the slave's TWSR sequences against the datasheet's status
// tables (ATmega328P §22.7 Tables 22-2..22-5, ATmega2560 §24.7, ATmega32
// §22.7), clock stretching, and the byte time from the bit-rate formula
// (§22.5.2). Stock simavr 1.6 cannot run this pair: its slave never matches
// the master's address, so the master sees 0x20 for every SLA+W.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "periph/twi/Twi.hpp"
#include "support/McuSuffix.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

std::string pair_board(const std::string& mcu_type) {
    const TwiPins pins = twi_pins(mcu_type);
    return "mcus:\n  master: {type: " + mcu_type + ", clock: 16MHz}\n  slave: {type: " + mcu_type +
           ", clock: 16MHz}\n"
           "parts:\n  sda_pull_up: {type: pull_resistor, to: vcc, resistance: 4.7kohm}\n"
           "  scl_pull_up: {type: pull_resistor, to: vcc, resistance: 4.7kohm}\n"
           "nets:\n  sda: [master." + pins.sda + ", slave." + pins.sda + ", sda_pull_up.pin]\n"
           "  scl: [master." + pins.scl + ", slave." + pins.scl + ", scl_pull_up.pin]\n";
}

std::vector<int> as_ints(const std::vector<std::uint8_t>& bytes) { return {bytes.begin(), bytes.end()}; }

void expect_pair_talks(const std::string& mcu_type) {
    const std::string suffix = test::firmware_suffix(mcu_type);
    Board board(parse_board_text(pair_board(mcu_type), "twi-pair.yaml"),
                {{"master", test::firmware("twi_master" + suffix)}, {"slave", test::firmware("twi_slave" + suffix)}});
    ASSERT_EQ(board.twi_buses().size(), 1u);
    std::vector<TwiEvent> events;
    board.mcu("master").twi()->on_event([&events](const TwiEvent& e) { events.push_back(e); });
    // The whole exchange is 24 bytes and 13 conditions at 100 kHz, about
    // 2.5 ms with the 100 us stretch; 20 ms leaves room.
    board.run_for_seconds(0.020);
    Mcu& master = board.mcu("master");
    Mcu& slave = board.mcu("slave");
    ASSERT_EQ(master.read_ram_u8("done"), 1)
        << mcu_type << ": master log " << ::testing::PrintToString(as_ints(master.read_ram("status_log", 24)))
        << ", slave log " << ::testing::PrintToString(as_ints(slave.read_ram("slave_log", 24)));

    EXPECT_EQ(master.read_ram_u8("twwc_seen"), 1) << "TWDR written with TWINT low sets TWWC (§22.9.2)";

    // Table 22-2 (MT) and 22-3 (MR), transaction by transaction (see main.c).
    const std::vector<int> master_expected = {0x08, 0x20,                                // absent slave
                                              0x08, 0x18, 0x28, 0x28, 0x30,              // write, third NACKed
                                              0x08, 0x18, 0x28, 0x10, 0x40, 0x50, 0x58,  // pointer, read two
                                              0x08, 0x18, 0x28};                         // general call
    ASSERT_EQ(master.read_ram_u8("status_count"), master_expected.size());
    EXPECT_EQ(as_ints(master.read_ram("status_log", master_expected.size())), master_expected) << mcu_type;

    // Tables 22-4 (SR) and 22-5 (ST).
    const std::vector<int> slave_expected = {0x60, 0x80, 0x80, 0x88,              // no 0xA0: not addressed after 0x88
                                             0x60, 0x80, 0xA0, 0xA8, 0xB8, 0xC0,  // repeated START, then read
                                             0x70, 0x90, 0xA0};                   // general call, STOP
    ASSERT_EQ(slave.read_ram_u8("slave_count"), slave_expected.size());
    EXPECT_EQ(as_ints(slave.read_ram("slave_log", slave_expected.size())), slave_expected) << mcu_type;

    EXPECT_EQ(as_ints(slave.read_ram("received", 3)), (std::vector<int>{0xA1, 0xB2, 0x01}));
    EXPECT_EQ(slave.read_ram_u8("nacked_byte"), 0xC3);
    EXPECT_EQ(slave.read_ram_u8("general_call_byte"), 0x5A);
    // The slave's table from pointer 1: 0x22, 0x33.
    EXPECT_EQ(as_ints(master.read_ram("read_back", 2)), (std::vector<int>{0x22, 0x33}));

    // SCL period = 16 + 2 * TWBR * 4^TWPS = 16 + 2 * 72 = 160 cycles
    // (100 kHz at 16 MHz); a byte and its ACK are 9 periods = 1440 cycles.
    // Around it, the firmware's own instructions between its two TCNT1
    // reads (twi_master.lst): LDS, LDI, STS before the TWCR write takes
    // effect (5), CALL (4-5), the polling loop (up to 5 a turn), logging the
    // status (~16), RET (4-5), LDS: between 10 and 40 cycles.
    const unsigned addr_nack = master.read_ram_u16("cycles_addr_nack");
    EXPECT_GE(addr_nack, 1440u + 10u);
    EXPECT_LE(addr_nack, 1440u + 40u);
    // The slave holds SCL for its 100 us delay (1600 cycles) after the ISR's
    // entry, then the byte takes 1440 (3040), plus the slave's interrupt
    // response and prologue before its delay starts (4-5 + ~20 cycles) and
    // its TWCR write after (~10), plus the master's 10-40 above, minus the
    // master's own return from the address byte (it starts its byte ~30
    // cycles after the slave's TWINT was set).
    const unsigned stretched = master.read_ram_u16("cycles_stretched");
    EXPECT_GE(stretched, 3040u);
    EXPECT_LE(stretched, 3040u + 80u);

    // The bus events the master saw: 4 STARTs + 1 repeated, 5 address bytes
    // (one NACKed), 7 data bytes, 4 STOPs.
    EXPECT_EQ(events.size(), 5u + 5u + 7u + 4u);
    EXPECT_EQ(events[1].kind, TwiEvent::Kind::Address);
    EXPECT_EQ(events[1].byte, 0x50 << 1);
    EXPECT_FALSE(events[1].acked);
}

TEST(TwiPair, StatusCodesAndStretchingAtmega328p) { expect_pair_talks("atmega328p"); }
TEST(TwiPair, StatusCodesAndStretchingAtmega2560) { expect_pair_talks("atmega2560"); }
TEST(TwiPair, StatusCodesAndStretchingAtmega32) { expect_pair_talks("atmega32"); }

TEST(TwiPair, SdaSharedWithoutSclIsAWiringError) {
    const std::string text = R"(mcus:
  a: {type: atmega328p, clock: 16MHz}
  b: {type: atmega328p, clock: 16MHz}
parts:
  scl_pull_up: {type: pull_resistor, to: vcc, resistance: 4.7kohm}
nets:
  sda: [a.PC4, b.PC4]
  scl_a: [a.PC5, scl_pull_up.pin]
)";
    try {
        Board board(parse_board_text(text, "half-bus.yaml"),
                    {{"a", test::firmware("twi_master")}, {"b", test::firmware("twi_slave")}});
        FAIL() << "expected BadInput";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("half-bus.yaml:7: net 'sda' joins the TWI SDA pins of a and b"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace avrbench
