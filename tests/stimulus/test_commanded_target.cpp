// CommandedTarget: which lines tell the bench, beyond doubt, where a G0/G1
// move goes. Expected values are the lines' own numbers; the cases are the
// ways a firmware's number parsing (atof, strtod) can read more into a line
// than the G-code grammar does.
#include <gtest/gtest.h>

#include <array>
#include <optional>

#include "stimulus/CommandedTarget.hpp"

namespace avrbench {
namespace {

using Xyz = std::optional<std::array<double, 3>>;

TEST(CommandedTarget, AMoveNamingAllThreeAxesIsATarget) {
    CommandedTarget t;
    EXPECT_EQ(t.accept("G1 X10 Y-6.7 Z-340"), (Xyz{{10.0, -6.7, -340.0}}));
    EXPECT_EQ(t.accept("G0X.5Y+2Z-300."), (Xyz{{0.5, 2.0, -300.0}}));
    EXPECT_EQ(t.accept("N12 G1 X1 Y2 Z-3*57"), (Xyz{{1.0, 2.0, -3.0}}));  // Marlin's line number and checksum
}

TEST(CommandedTarget, MissingAxesKeepTheirLastValueOnceKnown) {
    CommandedTarget t;
    EXPECT_EQ(t.accept("G1 X10"), std::nullopt);  // Y and Z never given
    EXPECT_EQ(t.accept("G1 Y20 Z-310"), (Xyz{{10.0, 20.0, -310.0}}));
    EXPECT_EQ(t.accept("M3"), std::nullopt);
    EXPECT_EQ(t.accept("G1 Z-320 F3000"), (Xyz{{10.0, 20.0, -320.0}}));
}

TEST(CommandedTarget, LinesAFirmwareMayReadDifferentlyForgetTheAxes) {
    for (const char* odd : {"G1 X1E3 Y0 Z-310",    // atof: X = 1000
                            "G1 X1e3 Y0 Z-310",    // lower case
                            "G1 X5 Y0 Z-310 ;Z-1", // a word in a comment
                            "G1 X5 X6 Y0 Z-310",   // first or last X?
                            "G1 X33Y-67-Z-292",    // a stray sign
                            "G1 X0x10 Y0 Z-310",   // hex
                            "G1 X5.5.5 Y0 Z-310",  // two points
                            "G1 X Y0 Z-310",       // no number
                            "G1 X1 Y2 Z-3*"}) {    // empty checksum
        CommandedTarget t;
        ASSERT_TRUE(t.accept("G1 X0 Y0 Z-300").has_value());
        EXPECT_EQ(t.accept(odd), std::nullopt) << odd;
        EXPECT_EQ(t.accept("G1 Z-310"), std::nullopt) << "after " << odd << " X and Y are unknown";
    }
}

TEST(CommandedTarget, RelativeInchesHomingAndOffsetsAreNotTargets) {
    CommandedTarget t;
    ASSERT_TRUE(t.accept("G1 X0 Y0 Z-300").has_value());
    EXPECT_EQ(t.accept("G91"), std::nullopt);
    EXPECT_EQ(t.accept("G1 X1 Y1 Z1"), std::nullopt);
    EXPECT_EQ(t.accept("G90"), std::nullopt);
    EXPECT_EQ(t.accept("G1 Z-300"), std::nullopt);  // X and Y forgotten in relative mode
    EXPECT_EQ(t.accept("G1 X1 Y2 Z-300"), (Xyz{{1.0, 2.0, -300.0}}));
    EXPECT_EQ(t.accept("G20"), std::nullopt);
    EXPECT_EQ(t.accept("G1 X1 Y2 Z-3"), std::nullopt);
    EXPECT_EQ(t.accept("G21"), std::nullopt);
    EXPECT_EQ(t.accept("G1 X1 Y2 Z-300"), (Xyz{{1.0, 2.0, -300.0}}));
    EXPECT_EQ(t.accept("G4 P100"), std::nullopt);  // a dwell keeps the position
    EXPECT_EQ(t.accept("G1 Z-310"), (Xyz{{1.0, 2.0, -310.0}}));
    for (const char* lost : {"G28", "G92 X0", "G2 X1 Y1 I1 J0", "X5"}) {
        EXPECT_EQ(t.accept(lost), std::nullopt) << lost;
        EXPECT_EQ(t.accept("G1 Z-310"), std::nullopt) << "after " << lost;
        ASSERT_TRUE(t.accept("G1 X1 Y2 Z-300").has_value());
    }
}

}  // namespace
}  // namespace avrbench
