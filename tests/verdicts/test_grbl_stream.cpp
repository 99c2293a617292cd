// False reds from a streamed grbl job (the grbl 1.1h campaign of issue 68,
// docs/THIRD_PARTY.md): what grbl refuses and what its realtime bytes do
// must reach the motion judge as grbl takes them. grbl_stream
// (firmware/verdicts) answers and moves as its header says; the board is the
// CNC shield (250 steps/mm, carriages start at 100 mm), with its own host:
// character counting into a 128-byte buffer, so lines go out before the
// answers to the ones before them come back.
#include <gtest/gtest.h>

#include "parts/MotionOracle.hpp"
#include "run/Bench.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

std::vector<const Finding*> not_host(const std::vector<Finding>& findings) {
    std::vector<const Finding*> out;
    for (const Finding& f : findings) {
        if (f.kind != UartHost::kHostProtocol) out.push_back(&f);
    }
    return out;
}

TEST(GrblStream, ALaterRefusedLineThatStoppedTheJudgingDoesNotLoseTheLinesBetween) {
    // All four lines go out at once (43 bytes of 128). Line 1 comes back
    // error:22, line 3 error:1. When line 1 is refused, line 3 ("5", no
    // letter) has already stopped the judging; line 2 is read again and must
    // be judged, and line 4 from where line 2 ends (X0.2), not from X0.
    Bench bench("arduino-uno-cnc-shield-v3", test::firmware("grbl_stream"));
    bench.host().add_lines("G1 X1 Y0.3 F0\nG1 X0.2 Y0\n5\nG1 X0.4 Y0\n");
    ASSERT_EQ(bench.run_until_idle(10.0), IdleResult::Idle) << bench.host().tail(6);
    EXPECT_EQ(bench.host().errors(), 2u);
    EXPECT_TRUE(bench.host().line_errored(0));
    EXPECT_TRUE(bench.host().line_errored(2));
    for (const Finding* f : not_host(bench.findings())) ADD_FAILURE() << f->describe();
    // 0.2 mm then 0.2 mm more at 250 steps/mm: 100 steps in all.
    EXPECT_NEAR(bench.axis("x").position_mm(), 100.4, 1e-9);
    const auto& oracle = bench.board().part_as<MotionOracle>("motion");
    EXPECT_TRUE(oracle.judging());
    EXPECT_EQ(oracle.moves_judged(), 2u);
}

TEST(GrblStream, AFeedHoldSentOnItsOwnStopsTheJudgingOfTheMoveUnderWay) {
    // G1 X4: 1000 step events of 400 us. Once the carriage is 1 mm on, '!'
    // goes out on its own: the machine stops where it is, short of X4,
    // which is grbl's to do and no finding.
    Bench bench("arduino-uno-cnc-shield-v3", test::firmware("grbl_stream"));
    bench.host().add_lines("G1 X4 Y0\n");
    for (int i = 0; i < 200 && bench.axis("x").position_mm() < 101.0; ++i) bench.run_for(0.01);
    ASSERT_GE(bench.axis("x").position_mm(), 101.0);
    bench.host().send_bytes("!");
    ASSERT_EQ(bench.run_until_idle(10.0), IdleResult::Idle) << bench.host().tail(6);
    EXPECT_LT(bench.axis("x").position_mm(), 102.0);  // held: 1 to 1.01 mm on, within a step event of the '!'
    for (const Finding& f : bench.findings()) ADD_FAILURE() << f.describe();
    EXPECT_FALSE(bench.board().part_as<MotionOracle>("motion").judging());
}

TEST(GrblStream, AFeedHoldInALaterLineStopsTheJudgingOfTheMovesBeforeIt) {
    // Line 2 carries '!': grbl takes it out as it arrives, before line 1's
    // move has begun. grbl_stream then holds before its first step event
    // and, making its moves one at a time, never reads line 2: the job is
    // still going for the host's sake only, not for a move the judge waits
    // for, and nothing is a finding.
    Bench bench("arduino-uno-cnc-shield-v3", test::firmware("grbl_stream"));
    bench.host().add_lines("G1 X4 Y0\nG4 P0 !\n");
    EXPECT_EQ(bench.run_until_idle(2.0), IdleResult::TimeLimit);
    EXPECT_LT(bench.axis("x").position_mm(), 100.1);
    for (const Finding& f : bench.findings()) ADD_FAILURE() << f.describe();
    EXPECT_FALSE(bench.board().part_as<MotionOracle>("motion").judging());
    std::vector<std::string> going;
    EXPECT_TRUE(bench.still_going(kPsPerMs * 50, &going));
    ASSERT_EQ(going.size(), 1u);
    EXPECT_NE(going[0].find("line 2 'G4 P0 !' not answered"), std::string::npos) << going[0];
}

// Arcs told to the oracle by hand: a half circle of radius 5 about (5, 0)
// is judged; an arc from (10, 0) about (3, 0) to (0, 0) starts 7 mm and
// ends 3 mm from its centre, which grbl refuses (error:33) and Marlin draws
// its own way: judging stops, and comes back when the line is refused.
TEST(GrblStream, AnArcWhoseEndIsOffItsCircleIsNotJudged) {
    Bench bench("arduino-uno-cnc-shield-v3", test::firmware("grbl_stream"));
    auto& oracle = bench.board().part_as<MotionOracle>("motion");
    bench.run_for(0.01);
    CommandedMove half;
    half.kind = CommandedMove::Kind::ArcClockwise;
    half.from_mm = {0.0, 0.0, 0.0};
    half.to_mm = {10.0, 0.0, 0.0};
    half.centre_mm = {5.0, 0.0};
    half.line = "line 1 'G2 X10 Y0 I5 J0'";
    oracle.commanded(half);
    EXPECT_TRUE(oracle.judging());
    CommandedMove off = half;
    off.from_mm = {10.0, 0.0, 0.0};
    off.to_mm = {0.0, 0.0, 0.0};
    off.centre_mm = {3.0, 0.0};
    off.line = "line 2 'G2 X0 Y0 I-7 J0'";
    oracle.commanded(off);
    EXPECT_FALSE(oracle.judging());
    EXPECT_NE(oracle.summary().find("line 2 'G2 X0 Y0 I-7 J0' is an arc whose end is off its circle (radius 7.000 mm at "
                                    "the start, 3.000 mm at the end)"),
              std::string::npos)
        << oracle.summary();
    EXPECT_TRUE(oracle.retract(1, false));
    EXPECT_TRUE(oracle.judging());
}

}  // namespace
}  // namespace avrbench
