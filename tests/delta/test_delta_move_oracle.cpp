// The bench's check of the moves a delta firmware accepts (parts/DeltaRobot
// check_accepted_move, wired to the host by run/Bench): a G1 answered ok
// must be a point the arms reach with every servo inside its travel.
// Targets and angles by hand from the thesis' inverse kinematics (digest
// seed_004_delta.md §2, f = 233.2, e = 80, r_f = 60, r_e = 350 mm), with the
// firmware's offsets 111/110/116 deg and Table 4.1's 0..180 deg travel:
//   (100, -67, -340): theta 6.34, 10.45, 57.43 -> horns 104.7, 99.5, 58.6 (digest §8.4)
//   (0, 151, -360):   theta1 111.82 -> horn1 = 111 - 111.82 = -0.82 deg (< 0 - 0.6)
//   (0, 151, -500):   no real elbow for any arm (the discriminant is negative)
//   (33, -67, -290):  theta1 -76.46 -> horn1 = 111 + 76.46 = 187.46 deg (> 180 + 0.6)
//   (33, -67, 0), (33, -67, 310): at and above the base plane (the robot hangs below it)
// Each test runs under ctest's 300 s wall-clock limit (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "parts/DeltaRobot.hpp"
#include "support/Paths.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

std::vector<std::string> reach_findings(const std::string& firmware, const std::string& lines) {
    Bench bench(test::source_path("bench/boards/delta-seed004.yaml"), test::firmware(firmware));
    bench.host().add_lines(lines);
    bench.run_until_idle(10.0);
    EXPECT_TRUE(bench.host().done()) << bench.host().tail(10);
    std::vector<std::string> out;
    for (const auto& f : bench.board().findings()) {
        if (f.kind == DeltaRobot::kTargetOutOfReach) out.push_back(f.describe());
    }
    return out;
}

const char* const kJob =
    "G1 X100 Y-67 Z-340\n"
    "G1 X0 Y151 Z-360\n"
    "G1 Z-500\n"
    "G1 X33 Y-67 Z-290\n"
    "G1 Z0\n"
    "G1 Z310\n";

TEST(DeltaMoveOracle, TheListingsBuildAcceptsFiveMovesTheRobotCannotMake) {
    const auto found = reach_findings("delta_thesis", kJob);
    ASSERT_EQ(found.size(), 5u);
    EXPECT_NE(found[0].find("robot: target-out-of-reach"), std::string::npos) << found[0];
    EXPECT_NE(found[0].find("arm 1 beyond its servo's travel; line 2 'G1 X0 Y151 Z-360' was answered ok, target (0.000, "
                            "151.000, -360.000) mm needs servo1 at -0.8 deg, its travel 0..180 deg"),
              std::string::npos)
        << found[0];
    EXPECT_NE(found[1].find("no pose of the arms below the base reaches the target; line 3 'G1 Z-500' was answered ok, target (0.000, "
                            "151.000, -500.000) mm"),
              std::string::npos)
        << found[1];
    EXPECT_NE(found[2].find("arm 1 beyond its servo's travel; line 4 'G1 X33 Y-67 Z-290' was answered ok, target "
                            "(33.000, -67.000, -290.000) mm needs servo1 at 187.5 deg"),
              std::string::npos)
        << found[2];
    EXPECT_NE(found[3].find("line 5 'G1 Z0' was answered ok, target (33.000, -67.000, 0.000) mm"), std::string::npos)
        << found[3];
    EXPECT_NE(found[4].find("line 6 'G1 Z310' was answered ok, target (33.000, -67.000, 310.000) mm"), std::string::npos)
        << found[4];
}

TEST(DeltaMoveOracle, TheImprovedBuildRefusesThemAndNothingIsFound) {
    EXPECT_TRUE(reach_findings("delta", kJob).empty());
}

TEST(DeltaMoveOracle, RightRefusalsAreNotHostFindingsButAWrongOneIs) {
    // The improved build answers "error: unreachable" to the five targets
    // above the robot cannot reach: right answers, so no finding at all (they
    // were five host-protocol findings with exit code 0, issue 40). A line
    // over 47 characters it refuses ("error: line too long") whose target
    // (100, -67, -340) the arms do reach stays one.
    Bench bench(test::source_path("bench/boards/delta-seed004.yaml"), test::firmware("delta"));
    bench.host().add_lines(std::string(kJob) + "G1 X100.000000000000 Y-67.000000000000 Z-340.0000000000\n");
    bench.run_until_idle(10.0);
    ASSERT_TRUE(bench.host().done()) << bench.host().tail(10);
    const auto findings = bench.findings();
    ASSERT_EQ(findings.size(), 1u);
    EXPECT_EQ(findings[0].kind, UartHost::kHostProtocol);
    EXPECT_NE(findings[0].detail.find("line 7"), std::string::npos) << findings[0].describe();
    EXPECT_NE(findings[0].detail.find("line too long"), std::string::npos) << findings[0].describe();
}

TEST(DeltaMoveOracle, ABoardForAnotherFrameTurnsTheCheckOff) {
    BoardSpec spec = load_board_file(test::source_path("bench/boards/delta-seed004.yaml"));
    for (auto& part : spec.parts) {
        if (part.name == "robot") part.params.push_back({"move_commands", "unchecked", "test"});
    }
    Bench bench(std::move(spec), {{"mega", test::firmware("delta_thesis")}});
    bench.host().add_lines(kJob);
    bench.run_until_idle(10.0);
    for (const auto& f : bench.board().findings()) EXPECT_NE(f.kind, DeltaRobot::kTargetOutOfReach) << f.describe();
}

}  // namespace
}  // namespace avrbench
