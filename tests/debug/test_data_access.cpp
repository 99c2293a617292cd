// Which data bytes an instruction touches (debug/DataAccess.hpp), for
// watchpoints. Encodings: the AVR Instruction Set Manual (DS40002198), each
// worked out by hand below; the first four are also the bytes avr-objdump
// shows in gdb_target.elf (little-endian words: "1d 92" is 0x921D).
#include <gtest/gtest.h>

#include <array>

#include "debug/DataAccess.hpp"

namespace avrbench {
namespace {

struct Data {
    std::array<std::uint8_t, 0x900> bytes{};
    Data() {
        bytes[26] = 0x00, bytes[27] = 0x02;  // X = 0x0200
        bytes[28] = 0x10, bytes[29] = 0x03;  // Y = 0x0310
        bytes[30] = 0x20, bytes[31] = 0x04;  // Z = 0x0420
        bytes[0x5D] = 0xFB, bytes[0x5E] = 0x08;  // SP = 0x08FB
    }
};

void expect_one(std::uint16_t opcode, std::uint16_t next, std::uint16_t address, bool write) {
    Data d;
    const auto accesses = data_accesses(opcode, next, d.bytes.data());
    ASSERT_EQ(accesses.size(), 1u) << std::hex << opcode;
    EXPECT_EQ(accesses[0].address, address) << std::hex << opcode;
    EXPECT_EQ(accesses[0].write, write) << std::hex << opcode;
}

TEST(DataAccess, DirectLoadsAndStoresUseTheSecondWord) {
    expect_one(0x9180, 0x0102, 0x0102, false);  // lds r24, 0x0102: 1001 000d dddd 0000
    expect_one(0x9390, 0x0103, 0x0103, true);   // sts 0x0103, r25: 1001 001r rrrr 0000
}

TEST(DataAccess, PointerModesAddressBeforeOrAfterTheirChange) {
    expect_one(0x921D, 0, 0x0200, true);    // st X+, r1: post-increment stores at X
    expect_one(0x900E, 0, 0x01FF, false);   // ld r0, -X: 1001 000d dddd 1110, pre-decrement reads X - 1
    expect_one(0x9009, 0, 0x0310, false);   // ld r0, Y+: 1001 000d dddd 1001
    expect_one(0x9202, 0, 0x041F, true);    // st -Z, r0: 1001 001r rrrr 0010
    // ldd r24, Y+5: 10q0 qq0d dddd 1qqq, q = 5 = 0 00 101, d = 24 = 11000 -> 1000 0001 1000 1101
    expect_one(0x818D, 0, 0x0315, false);
    // std Z+2, r18: 10q0 qq1r rrrr 0qqq, q = 2, r = 18 = 10010 -> 1000 0011 0010 0010
    expect_one(0x8322, 0, 0x0422, true);
    // ldd r0, Z+63: q = 63 = 1 11 111 -> 1010 1100 0000 0111
    expect_one(0xAC07, 0, 0x045F, false);
}

TEST(DataAccess, StackAndIoInstructions) {
    expect_one(0x93CF, 0, 0x08FB, true);   // push r28: 1001 001r rrrr 1111, writes at SP
    expect_one(0x91CF, 0, 0x08FC, false);  // pop r28: reads SP + 1
    expect_one(0xB984, 0, 0x0024, true);   // out 0x04 (DDRB), r24: I/O 0x04 is data 0x24
    expect_one(0xB583, 0, 0x0043, false);  // in r24, 0x23: 1011 0AAd dddd AAAA, A = 10 0011
    Data d;
    // sbi 0x05, 5: 1001 1010 AAAA Abbb -> reads and writes PORTB (data 0x25)
    const auto sbi = data_accesses(0x9A2D, 0, d.bytes.data());
    ASSERT_EQ(sbi.size(), 2u);
    EXPECT_EQ(sbi[0].address, 0x25);
    EXPECT_FALSE(sbi[0].write);
    EXPECT_TRUE(sbi[1].write);
    // sbis 0x03, 0 (PINB): read only
    const auto sbis = data_accesses(0x9B18, 0, d.bytes.data());
    ASSERT_EQ(sbis.size(), 1u);
    EXPECT_EQ(sbis[0].address, 0x23);
}

TEST(DataAccess, OtherInstructionsTouchNoData) {
    Data d;
    const std::uint16_t none[] = {0x0000, 0x9508 /* ret */, 0x9603 /* adiw r24, 3 */, 0x95C8 /* lpm */, 0x9005 /* lpm r0, Z+ */};
    for (std::uint16_t op : none) {
        EXPECT_TRUE(data_accesses(op, 0, d.bytes.data()).empty()) << std::hex << op;
    }
}

}  // namespace
}  // namespace avrbench
