// stimulus/GcodeMutator: every mutation the fuzzing issue asks for happens,
// each does what its name says on a known line, the size limit holds and
// the same seed gives the same bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <string>

#include "stimulus/GcodeMutator.hpp"

namespace avrbench {
namespace {

std::size_t reverse_bytes(std::uint8_t* data, std::size_t size, std::size_t) {
    std::reverse(data, data + size);
    return size;
}

struct Mutated {
    std::string text;
    GcodeMutation kind;
};

Mutated mutate(const std::string& input, unsigned seed, std::size_t max_size = 1024) {
    std::string buffer = input;
    buffer.resize(std::max(max_size, input.size()));
    GcodeMutation kind{};
    const std::size_t n = mutate_gcode(reinterpret_cast<std::uint8_t*>(buffer.data()), input.size(), max_size, seed,
                                       &reverse_bytes, &kind);
    buffer.resize(n);
    return {buffer, kind};
}

TEST(GcodeMutator, MakesEveryKindOfMutationAndEachDoesWhatItSays) {
    const std::string line = "G1 X5 Y5 F600\n";
    std::map<GcodeMutation, int> seen;
    for (unsigned seed = 0; seed < 3000; ++seed) {
        const Mutated m = mutate(line, seed);
        ++seen[m.kind];
        switch (m.kind) {
            case GcodeMutation::DropWord:
                EXPECT_EQ(m.text, "G1 X5 Y5 \n") << "the F word goes first";
                break;
            case GcodeMutation::OverlongLine:
                EXPECT_GE(m.text.size(), 51u) << m.text;
                EXPECT_EQ(m.text.rfind(line.substr(0, line.size() - 1), 0), 0u) << "the line is padded, not replaced";
                break;
            case GcodeMutation::DuplicateLine:
                EXPECT_EQ(m.text, line + line);
                break;
            case GcodeMutation::DegenerateArc:
                EXPECT_TRUE(m.text.rfind("G2", 0) == 0 || m.text.rfind("G3", 0) == 0) << m.text;
                break;
            case GcodeMutation::BinaryByte:
                EXPECT_EQ(m.text.size(), line.size() + 1);
                break;
            case GcodeMutation::ExtremeNumber:
                // One of the words' numbers replaced: the letters stay in place.
                EXPECT_EQ(m.text[0], 'G') << m.text;
                EXPECT_NE(m.text, line);
                break;
            case GcodeMutation::NearbyNumber: {
                // Words' numbers replaced by whole numbers: 1 (G1) within
                // [-99, 101], 5 within [-95, 105], 600 within [-2400, 2400]:
                // at most 2 more characters per word.
                EXPECT_EQ(m.text.rfind("G", 0), 0u) << m.text;
                EXPECT_LE(m.text.size(), line.size() + 8) << m.text;
                EXPECT_EQ(m.text.find_first_not_of("GXYF0123456789- \n"), std::string::npos) << m.text;
                break;
            }
            case GcodeMutation::ByteLevel:
                EXPECT_EQ(m.text, std::string(line.rbegin(), line.rend())) << "the fallback's bytes, untouched";
                break;
            default:
                EXPECT_GT(m.text.size(), line.size()) << to_string(m.kind);
        }
    }
    for (int k = 0; k <= static_cast<int>(GcodeMutation::ByteLevel); ++k) {
        EXPECT_GT(seen[static_cast<GcodeMutation>(k)], 100) << to_string(static_cast<GcodeMutation>(k));
    }
}

TEST(GcodeMutator, ExtremeNumbersIncludeTheIssuesExamples) {
    std::map<std::string, bool> found{{"X1e9", false}, {"X-0\n", false}, {"X99999999999", false}};
    for (unsigned seed = 0; seed < 5000; ++seed) {
        const Mutated m = mutate("G1 X5\n", seed);
        if (m.kind != GcodeMutation::ExtremeNumber) continue;
        for (auto& [text, hit] : found) hit = hit || m.text.find(text) != std::string::npos;
    }
    for (const auto& [text, hit] : found) EXPECT_TRUE(hit) << text;
}

TEST(GcodeMutator, NearbyNumbersStayWithinAFewTimesTheOriginal) {
    // From X-33 (mm): scaled by -4..4 gives -132..132, shifted by up to
    // max(100, 66) gives -133..67; all within [-133, 133], and both signs come up.
    bool negative = false, positive = false, moved = false;
    for (unsigned seed = 0; seed < 3000; ++seed) {
        const Mutated m = mutate("G1 X-33\n", seed);
        if (m.kind != GcodeMutation::NearbyNumber) continue;
        const long x = std::strtol(m.text.c_str() + m.text.find('X') + 1, nullptr, 10);
        EXPECT_GE(x, -133) << m.text;
        EXPECT_LE(x, 133) << m.text;
        negative = negative || x < 0;
        positive = positive || x > 0;
        moved = moved || x != -33;
    }
    EXPECT_TRUE(negative && positive && moved);
}

TEST(GcodeMutator, NearbyNumbersOftenStayCloseToTheOriginal) {
    // A limit just past a job's targets needs small moves often: from X-33,
    // the nudge (a third of the nearby mutations) lands in -33 * (0.9..1.1)
    // -+ 5 = [-41.3, -24.7] always; scaling (0.8..1.2 of the 81 factors) and
    // shifting (16 of 200 units) add about 2 % more. Together about a third:
    // at least a fifth, over ~300 mutations, leaves room for chance.
    int nearby = 0, close = 0;
    for (unsigned seed = 0; seed < 3000; ++seed) {
        const Mutated m = mutate("G1 X-33\n", seed);
        if (m.kind != GcodeMutation::NearbyNumber) continue;
        ++nearby;
        const long x = std::strtol(m.text.c_str() + m.text.find('X') + 1, nullptr, 10);
        if (x >= -41 && x <= -25 && x != -33) ++close;
    }
    ASSERT_GT(nearby, 200);
    EXPECT_GT(close * 5, nearby) << close << " of " << nearby;
}

TEST(GcodeMutator, KeepsToTheSizeLimitAndIsDeterministic) {
    for (unsigned seed = 0; seed < 500; ++seed) {
        EXPECT_LE(mutate("G1 X5 Y5 F600\nM105\n", seed, 20).text.size(), 20u);
        EXPECT_EQ(mutate("G28\nG1 X1\n", seed).text, mutate("G28\nG1 X1\n", seed).text);
    }
    EXPECT_LE(mutate("", 7).text.size(), 1024u);  // an empty input is a valid start
}

}  // namespace
}  // namespace avrbench
