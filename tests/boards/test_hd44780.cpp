// The hd44780 LCD part driven by our own firmware (firmware/boards/lcd_hello)
// on the Einsy RAMBo's display pins, in 4-bit mode as the HD44780U
// datasheet's Figure 24 initialises it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "parts/Hd44780.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

Board lcd_board(const std::string& firmware, const std::string& geometry) {
    const std::string text = R"(
board: lcd
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  lcd: {type: hd44780, geometry: )" + geometry + R"(}
nets:
  lcd_rs: [mega.PD5, lcd.rs]
  lcd_e: [mega.PF7, lcd.e]
  lcd_d4: [mega.PF5, lcd.d4]
  lcd_d5: [mega.PG4, lcd.d5]
  lcd_d6: [mega.PH7, lcd.d6]
  lcd_d7: [mega.PG3, lcd.d7]
)";
    return Board(parse_board_text(text, "lcd.yaml"), {{"mega", test::firmware(firmware)}});
}

TEST(Hd44780, ShowsWhatTheFirmwareWroteOnA20x4) {
    Board board = lcd_board("lcd_hello", "20x4");
    board.run_for_seconds(0.5);
    ASSERT_EQ(board.mcu().read_ram_u8("done"), 1);
    auto& lcd = dynamic_cast<Hd44780&>(board.part("lcd"));
    // Line 4 of a 20x4 is DDRAM 0x54 onwards (the second 40-character line
    // from its 20th character); 0xDF is the A00 ROM's degree sign.
    EXPECT_EQ(lcd.lines(), (std::vector<std::string>{"Hello, Einsy        ", "                    ",
                                                     "                    ", "Temp 215\u00B0C          "}));
    EXPECT_TRUE(board.findings().empty());
    // One burst of writes (every gap under the 20 ms screen_settle): one screen.
    const auto screens = lcd.screens();
    ASSERT_EQ(screens.size(), 1u);
    EXPECT_EQ(screens[0].lines, lcd.lines());
}

TEST(Hd44780, A16x2ShowsTheFirst16CharactersOfTheTwoLines) {
    Board board = lcd_board("lcd_hello", "16x2");
    board.run_for_seconds(0.5);
    auto& lcd = dynamic_cast<Hd44780&>(board.part("lcd"));
    // DDRAM 0x54 is past a 16x2's second line window (0x40..0x4F).
    EXPECT_EQ(lcd.lines(), (std::vector<std::string>{"Hello, Einsy    ", "                "}));
}

TEST(Hd44780, WritingBeforeAClearHasFinishedLosesTheWrites) {
    Board board = lcd_board("lcd_hello_too_early", "20x4");
    board.run_for_seconds(0.5);
    auto& lcd = dynamic_cast<Hd44780&>(board.part("lcd"));
    std::vector<std::string> kinds;
    for (const auto& f : board.findings()) kinds.emplace_back(f.kind.name());
    EXPECT_EQ(kinds, std::vector<std::string>{"lcd-write-while-busy"});
    // The clear takes 1.52 ms; the entry mode set and the display-on 50 us
    // after it were lost, so the display stayed off.
    EXPECT_FALSE(lcd.display_on());
}

}  // namespace
}  // namespace avrbench

#include <fstream>

#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

TEST(Hd44780, TheHtmlReportShowsTheScreensWithTheirTimes) {
    const auto dir = test::scratch_dir("lcd-report");
    const auto report = dir / "lcd.html";
    const auto r = test::run_command(std::string(test::cli()) + " run " + std::string(test::firmware("lcd_hello")) + " --board einsy-rambo --for 0.2s --report " +
                                         report.string(),
                                     dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(report);
    const std::string html((std::istreambuf_iterator<char>(in)), {});
    // One screen (a single burst of writes), its lines as the LCD shows them.
    EXPECT_NE(html.find("<section id=\"display-section\">"), std::string::npos);
    EXPECT_NE(html.find("id=\"display-lcd\""), std::string::npos);
    EXPECT_NE(html.find("<pre>Hello, Einsy        \n"), std::string::npos);
    EXPECT_NE(html.find("Temp 215\u00B0C"), std::string::npos);
}

}  // namespace
}  // namespace avrbench
