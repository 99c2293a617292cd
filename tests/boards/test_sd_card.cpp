// The sd_card part in SPI mode, brought up by our own firmware
// (firmware/boards/sd_probe) as Sd2Card does, on the Einsy RAMBo's SD pins.
// Expected bytes from the SD Physical Layer Simplified Specification (§7.3
// responses, §5.1 OCR, §5.3 CSD) and hand calculations beside them.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"
#include "parts/SdCard.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

// A 1 MiB image: "FAT!" at the start of block 0, the boot signature 55 AA
// at bytes 510 and 511, zeros elsewhere.
std::string make_image(const std::filesystem::path& dir) {
    std::string bytes(1 << 20, '\0');
    bytes.replace(0, 4, "FAT!");
    bytes[510] = '\x55';
    bytes[511] = '\xAA';
    const std::string path = (dir / "card.img").string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
}

// MISO (the card's DAT0/DO) has the pull-up the SD specification asks of
// the host (RDAT, 10-100 kOhm: "to prevent bus floating"). init_time 4 ms: one CMD55 + ACMD41 round is 18 bytes at 125 kHz (1.152 ms)
// and the firmware's 0.5 ms pause, about 1.655 ms; the 4th ACMD41 comes
// 3 * 1.655 = 4.97 ms after the first, the 3rd at 3.31 ms is still idle.
Board sd_board(const std::string& image, const std::string& extra) {
    const std::string text = R"(
board: sd
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  sd: {type: sd_card, image: ')" + image + "', init_time: 4ms" + extra + R"(}
  miso_pullup: {type: pull_resistor, to: vcc, resistance: 47kohm}
nets:
  sck: [mega.PB1, sd.sck]
  mosi: [mega.PB2, sd.mosi]
  miso: [mega.PB3, sd.miso, miso_pullup.pin]
  sd_cs: [mega.PJ6, sd.cs]
  sd_detect: [mega.PJ0, sd.detect]
)";
    return Board(parse_board_text(text, "sd.yaml"), {{"mega", test::firmware("sd_probe")}});
}

std::vector<std::uint8_t> bytes(const char* s) { return std::vector<std::uint8_t>(s, s + std::char_traits<char>::length(s)); }

TEST(SdCard, ComesUpInSpiModeAndReadsAndWritesBlocks) {
    const auto dir = test::scratch_dir("sd-card");
    const std::string image = make_image(dir);
    Board board = sd_board(image, "");
    board.run_for_seconds(1);
    Mcu& m = board.mcu();
    ASSERT_EQ(m.read_ram_u8("done"), 1);
    EXPECT_EQ(m.read_ram_u8("card_detect"), 0);  // the slot's switch closed to GND
    EXPECT_EQ(m.read_ram_u8("r1_cmd0"), 0x01);   // R1: in idle state
    // CMD8's R7: R1 idle, then the voltage accepted (1: 2.7-3.6 V) and the check pattern 0xAA echoed.
    EXPECT_EQ(m.read_ram("r7", 5), (std::vector<std::uint8_t>{0x01, 0x00, 0x00, 0x01, 0xAA}));
    EXPECT_EQ(m.read_ram_u16("acmd41_tries"), 4);
    // R1 0, OCR: power-up done (bit 31), CCS for SDHC (bit 30), 2.7-3.6 V (bits 23:15).
    EXPECT_EQ(m.read_ram("ocr", 5), (std::vector<std::uint8_t>{0x00, 0xC0, 0xFF, 0x80, 0x00}));
    // CSD 2.0 (byte 0 = 0x40); C_SIZE = 1 MiB / 512 KiB - 1 = 1 in bytes 7..9; the end bit.
    const auto csd = m.read_ram("csd", 16);
    EXPECT_EQ(csd[0], 0x40);
    EXPECT_EQ((std::vector<std::uint8_t>{csd[7], csd[8], csd[9]}), (std::vector<std::uint8_t>{0, 0, 1}));
    EXPECT_EQ(csd[15] & 1, 1);
    EXPECT_EQ(m.read_ram("block0_head", 4), bytes("FAT!"));
    EXPECT_EQ(m.read_ram("block0_tail", 2), (std::vector<std::uint8_t>{0x55, 0xAA}));
    EXPECT_EQ(m.read_ram_u8("write_response"), 0x05);  // data accepted (§7.3.3.1)
    EXPECT_EQ(m.read_ram("block1_head", 4), bytes("AVRB"));
    EXPECT_TRUE(board.findings().empty());
    // The card's copy changed, the user's image did not.
    auto& sd = dynamic_cast<SdCard&>(board.part("sd"));
    EXPECT_EQ(sd.blocks_written(), 1u);
    std::ifstream in(image, std::ios::binary);
    std::string after((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(after.substr(512, 4), std::string(4, '\0'));
}

TEST(SdCard, AStandardCapacityCardTakesByteAddresses) {
    const auto dir = test::scratch_dir("sd-card-sdsc");
    Board board = sd_board(make_image(dir), ", card: sdsc");
    board.run_for_seconds(1);
    Mcu& m = board.mcu();
    // OCR without CCS: 0x80FF8000; CSD 1.0 (byte 0 = 0x00); block 1 at byte 512.
    EXPECT_EQ(m.read_ram("ocr", 5), (std::vector<std::uint8_t>{0x00, 0x80, 0xFF, 0x80, 0x00}));
    EXPECT_EQ(m.read_ram("csd", 1)[0], 0x00);
    EXPECT_EQ(m.read_ram("block1_head", 4), bytes("AVRB"));
}

TEST(SdCard, AnEmptySlotAnswersNothing) {
    const auto dir = test::scratch_dir("sd-card-empty");
    Board board = sd_board(make_image(dir), ", inserted: no");
    board.run_for_seconds(1);
    // The detect switch open: the pull-up reads 1; CMD0 gets no R1 within 8
    // bytes (nobody drives MISO: its pull-up makes every byte 0xFF).
    EXPECT_EQ(board.mcu().read_ram_u8("card_detect"), 1u << 0);
    EXPECT_EQ(board.mcu().read_ram_u8("r1_cmd0"), 0xFF);
}

TEST(SdCard, WithWriteBackTheFirmwaresBlocksReachTheImage) {
    const auto dir = test::scratch_dir("sd-card-write-back");
    const std::string image = make_image(dir);
    Board board = sd_board(image, ", write_back: \"yes\"");
    board.run_for_seconds(1);
    ASSERT_EQ(board.mcu().read_ram_u8("done"), 1);
    // sd_probe writes "AVRB" and 508 zeros to block 1 (bytes 512..1023).
    const std::string after = test::slurp(image);
    EXPECT_EQ(after.size(), 1u << 20);
    EXPECT_EQ(after.substr(512, 4), "AVRB");
    EXPECT_EQ(after.substr(0, 4), "FAT!");
}

// The card on the Einsy's SPI pins, after a board file's parts.
const char* kSdNets = "nets:\n  sck: [mega.PB1, sd.sck]\n  mosi: [mega.PB2, sd.mosi]\n  miso: [mega.PB3, sd.miso]\n"
                      "  sd_cs: [mega.PJ6, sd.cs]\n";

// An image or folder named in a board file is found beside the board file,
// wherever avrbench runs (as an MCU's firmware is).
TEST(SdCard, AnImageIsFoundBesideTheBoardFileThatNamesIt) {
    const auto dir = test::scratch_dir("sd-card-relative");
    make_image(dir);
    std::ofstream(dir / "board.yaml") << "board: rel\nmcus:\n  mega: {type: atmega2560, clock: 16MHz}\n"
                                         "parts:\n  sd: {type: sd_card, image: card.img}\n" << kSdNets;
    Board board(load_board_file((dir / "board.yaml").string()), {{"mega", test::firmware("sd_probe")}});
    EXPECT_EQ(dynamic_cast<SdCard&>(board.part("sd")).contents().size(), 1u << 20);
}

TEST(SdCard, AFolderBecomesTheCardsFilesAndFolderErrorsNameTheFile) {
    const auto dir = test::scratch_dir("sd-card-folder");
    std::filesystem::create_directories(dir / "jobs");
    std::ofstream(dir / "jobs" / "part.gco") << "G1 X1\n";
    std::ofstream(dir / "board.yaml") << "board: f\nmcus:\n  mega: {type: atmega2560, clock: 16MHz}\n"
                                         "parts:\n  sd: {type: sd_card, folder: jobs}\n" << kSdNets;
    Board board(load_board_file((dir / "board.yaml").string()), {{"mega", test::firmware("sd_probe")}});
    const auto files = dynamic_cast<SdCard&>(board.part("sd")).stored_files();
    ASSERT_TRUE(files.has_value());
    ASSERT_EQ(files->size(), 1u);
    EXPECT_EQ((*files)[0].name, "PART.GCO");
    EXPECT_EQ((*files)[0].bytes, "G1 X1\n");

    std::ofstream(dir / "jobs" / "long-name.gcode") << "G1 X2\n";
    try {
        Board bad(load_board_file((dir / "board.yaml").string()), {{"mega", test::firmware("sd_probe")}});
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("'long-name.gcode' is not an 8.3 name"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace avrbench
