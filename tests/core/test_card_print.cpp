// The host lines that select and start a card print (Marlin's G-code
// reference: M23 "Select SD file", M24 "Start or Resume SD print"), read the
// way the bench hands the selected file's moves to the motion judges.
#include <gtest/gtest.h>

#include "run/CardPrint.hpp"

namespace avrbench {
namespace {

TEST(CardPrint, M23NamesTheFileAndM24StartsIt) {
    const auto select = card_print_command("M23 job.gco");
    ASSERT_TRUE(select.has_value());
    EXPECT_EQ(select->kind, CardPrintCommand::Kind::Select);
    EXPECT_EQ(select->file, "job.gco");
    const auto start = card_print_command("M24");
    ASSERT_TRUE(start.has_value());
    EXPECT_EQ(start->kind, CardPrintCommand::Kind::Start);
}

TEST(CardPrint, LineNumbersAndChecksumsAroundAreNotPartOfTheName) {
    // Marlin's host protocol: "N<line> <command>*<checksum>".
    const auto select = card_print_command("N12 M23 /JOB.GCO*71");
    ASSERT_TRUE(select.has_value());
    EXPECT_EQ(select->file, "/JOB.GCO");
    EXPECT_TRUE(card_print_command("n3 m24*5").has_value());
}

TEST(CardPrint, OtherCommandsAreNotCardPrints) {
    EXPECT_FALSE(card_print_command("M240").has_value());   // trigger a camera
    EXPECT_FALSE(card_print_command("M23").has_value());    // no file named
    EXPECT_FALSE(card_print_command("G1 X23").has_value());
    EXPECT_FALSE(card_print_command("N M24").has_value());  // "N" without a number
}

struct Card : StoredFiles {
    std::optional<std::vector<FatFile>> files;
    std::optional<std::vector<FatFile>> stored_files() const override { return files; }
};

TEST(CardPrint, TheFileIsFoundWhateverItsCaseAndTheReasonIsGivenWhenNot) {
    Card card;
    card.files = std::vector<FatFile>{{"JOB.GCO", "G1 X1\n"}};
    std::string why;
    EXPECT_EQ(card_file({&card}, "/job.gco", why), "G1 X1\n");
    EXPECT_FALSE(card_file({&card}, "other.gco", why).has_value());
    EXPECT_EQ(why, "prints 'other.gco', which is on no card in the root directory");
    Card unreadable;
    EXPECT_FALSE(card_file({&unreadable}, "job.gco", why).has_value());
    EXPECT_EQ(why, "prints from a card the bench cannot read (no card in the slot, or no FAT file system on it)");
    EXPECT_FALSE(card_file({}, "job.gco", why).has_value());
    EXPECT_EQ(why, "prints from a card, and the board has none");
}

}  // namespace
}  // namespace avrbench
