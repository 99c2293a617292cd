// The bench's one G-code reader (core/GcodeLexer.hpp). Expected words are
// read off each line by hand: letter, number, and the bytes [begin, end).
#include <gtest/gtest.h>

#include "core/GcodeLexer.hpp"

namespace avrbench {
namespace {

TEST(GcodeLexer, StrictReadsTouchingAndSpacedWordsAndAChecksum) {
    const auto words = lex_strict_gcode("N12 G1X10.5 Y-2*71");
    ASSERT_TRUE(words.has_value());
    ASSERT_EQ(words->size(), 4u);
    EXPECT_EQ((*words)[0].letter, 'N');
    EXPECT_EQ((*words)[0].value, 12);
    EXPECT_EQ((*words)[1].letter, 'G');
    EXPECT_EQ((*words)[1].value, 1);
    EXPECT_EQ((*words)[2].letter, 'X');
    EXPECT_EQ((*words)[2].value, 10.5);
    // "X10.5" is bytes 6..10 of the line: begin 6, end 11.
    EXPECT_EQ((*words)[2].begin, 6u);
    EXPECT_EQ((*words)[2].end, 11u);
    EXPECT_EQ((*words)[3].value, -2);
}

TEST(GcodeLexer, StrictRefusesWhatFirmwareReadDifferently) {
    // A comment, a lowercase letter, an exponent, a letter without a number,
    // an empty checksum: each read one way by one firmware and another by
    // the next.
    for (const char* line : {"G1 X1 ; move", "g1 x1", "G1 X1E2", "G1 X", "G1 X1*", "G1 X.", "G1 X1 (c)"}) {
        EXPECT_FALSE(lex_strict_gcode(line).has_value()) << line;
    }
    EXPECT_TRUE(lex_strict_gcode("").has_value());
    EXPECT_TRUE(lex_strict_gcode("G1 X.5").has_value());  // a fraction alone is a number
}

TEST(GcodeLexer, LenientReadsEveryLetteredNumberUpToAComment) {
    const auto words = lex_lenient_gcode("m104 s200 ; T1");
    ASSERT_EQ(words.size(), 2u);
    EXPECT_EQ(words[0].letter, 'M');
    EXPECT_EQ(words[0].value, 104);
    EXPECT_EQ(words[1].letter, 'S');
    EXPECT_EQ(words[1].value, 200);
    // Letters without numbers are skipped; '*' ends the words too.
    const auto more = lex_lenient_gcode("G4 P500 Q X*12");
    ASSERT_EQ(more.size(), 2u);
    EXPECT_EQ(more[1].letter, 'P');
    EXPECT_EQ(more[1].value, 500);
}

TEST(GcodeLexer, WordsMapKeepsTheFirstOfALetter) {
    const auto words = gcode_words("M104 S200 S100 T1");
    EXPECT_EQ(words.at('M'), 104);
    EXPECT_EQ(words.at('S'), 200);
    EXPECT_EQ(words.at('T'), 1);
    EXPECT_EQ(words.count('X'), 0u);
}

}  // namespace
}  // namespace avrbench
