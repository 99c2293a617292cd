// The spi_flash part as the Einsy RAMBo's XFLASH (W25X20CL), used by our own
// firmware (firmware/boards/xflash_probe) the way the datasheet's
// instructions and Prusa-Firmware's xflash.c use it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "parts/SpiBus.hpp"
#include "parts/SpiFlash.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

Board flash_board() {
    const char* text = R"(
board: flash
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  xflash: {type: spi_flash}
nets:
  sck: [mega.PB1, xflash.sck]
  mosi: [mega.PB2, xflash.mosi]
  miso: [mega.PB3, xflash.miso]
  xflash_cs: [mega.PC5, xflash.cs]
)";
    return Board(parse_board_text(text, "flash.yaml"), {{"mega", test::firmware("xflash_probe")}});
}

TEST(SpiFlash, AnswersItsIdsAsPrusaFirmwareExpectsThem) {
    Board board = flash_board();
    board.run_for_seconds(0.5);
    ASSERT_EQ(board.mcu().read_ram_u8("done"), 1);
    // JEDEC ID: Winbond 0xEF, W25X series 0x30, capacity 0x12 = 2^18 bytes
    // (256 KB); 0x90 at address 0: manufacturer 0xEF, device 0x11 (the values
    // Prusa-Firmware's xflash_init accepts for a W25X20CL).
    EXPECT_EQ(board.mcu().read_ram("jedec", 3), (std::vector<std::uint8_t>{0xEF, 0x30, 0x12}));
    EXPECT_EQ(board.mcu().read_ram("mfr_dev", 2), (std::vector<std::uint8_t>{0xEF, 0x11}));
}

TEST(SpiFlash, ASectorEraseIsBusyForItsTimeAndAPageProgramReadsBack) {
    Board board = flash_board();
    board.run_for_seconds(0.5);
    // 30 ms of BUSY (sector_erase_time) at Timer1 clk/64 = 4 us per tick:
    // 7500 ticks, plus at most one status poll (2 bytes at 1 MHz SCK and the
    // loop, under 40 us = 10 ticks).
    const unsigned ticks = board.mcu().read_ram_u16("erase_ticks");
    EXPECT_GE(ticks, 7500u);
    EXPECT_LE(ticks, 7510u);
    // "Hello" programmed into the erased page; the byte after it still 0xFF.
    EXPECT_EQ(board.mcu().read_ram("readback", 6), (std::vector<std::uint8_t>{'H', 'e', 'l', 'l', 'o', 0xFF}));
    // The second program had no Write Enable: a finding, and ignored (the
    // readback shows it changed nothing); WEL and BUSY clear at the end.
    std::vector<std::string> kinds;
    for (const auto& f : board.findings()) kinds.emplace_back(f.kind.name());
    EXPECT_EQ(kinds, std::vector<std::string>{"flash-write-not-enabled"});
    EXPECT_EQ(board.mcu().read_ram_u8("status_after"), 0x00);
    auto& flash = dynamic_cast<SpiFlash&>(board.part("xflash"));
    EXPECT_EQ(flash.programs(), 1u);
    EXPECT_EQ(flash.erases(), 1u);
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(SpiBus, SlavesSelectedTogetherAreContention) {
    // This firmware drives only the XFLASH's chip select: a TMC2130 whose CS
    // line has no pull-up floats, which the bench reads low (selected), so
    // every byte has two answers.
    const char* text = R"(
board: floating-cs
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  xflash: {type: spi_flash}
  x_driver: {type: tmc2130}
nets:
  sck: [mega.PB1, xflash.sck, x_driver.sck]
  mosi: [mega.PB2, xflash.mosi, x_driver.mosi]
  miso: [mega.PB3, xflash.miso, x_driver.miso]
  xflash_cs: [mega.PC5, xflash.cs]
  x_cs: [mega.PG0, x_driver.cs]
)";
    Board board(parse_board_text(text, "floating-cs.yaml"), {{"mega", test::firmware("xflash_probe")}});
    board.run_for_seconds(0.2);
    std::size_t contention = 0;
    std::string flash_detail;
    for (const auto& f : board.findings()) {
        if (f.kind != kSpiBusContention) continue;
        ++contention;
        if (f.source == "xflash") flash_detail = f.detail;
    }
    EXPECT_EQ(contention, 2u);  // once per slave that answered with another
    EXPECT_NE(flash_detail.find("selected together with x_driver"), std::string::npos) << flash_detail;
}

TEST(SpiBus, TheEinsyRamboChipSelectsArePulledUp) {
    // einsy-rambo's 10 kOhm pull-ups hold the chip selects this firmware never
    // drives high: only the XFLASH answers.
    Board board(load_board_file("einsy-rambo"), {{"mega", test::firmware("xflash_probe")}});
    board.run_for_seconds(0.2);
    for (const auto& f : board.findings()) EXPECT_NE(f.kind, kSpiBusContention) << f.detail;
    EXPECT_EQ(board.mcu().read_ram("jedec", 3), (std::vector<std::uint8_t>{0xEF, 0x30, 0x12}));
}

}  // namespace
}  // namespace avrbench
