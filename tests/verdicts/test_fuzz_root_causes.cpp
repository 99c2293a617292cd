// One distinct finding of a fuzz campaign is one root cause
// (bench/fuzz/FuzzFindings.hpp): what the firmware did, named the same
// however the fuzzer varied the input. The texts below are findings as the
// bench words them (the grbl 1.1h and grbl_stepper campaigns of issue 68).
#include <gtest/gtest.h>

#include "fuzz/FuzzFindings.hpp"

namespace avrbench {
namespace {

TEST(FuzzRootCauses, ACrashIsItsKindInItsFunction) {
    EXPECT_EQ(finding_root_cause("avrbench fuzz: FINDING after 28672 AVR instructions: uno: stack-overflow at 0.628294 s "
                                 "(cycle 10052704), PC 0x64e8 __vector_11+0xc: SP 0x075f is below the end of .data/.bss"),
              "uno: stack-overflow in __vector_11");
}

TEST(FuzzRootCauses, ALineFindingIsItsKindOnTheLinesCommand) {
    EXPECT_EQ(finding_root_cause("motion: path-deviation at 0.6 s (cycle 9705273): line 4 'G3X05J5': the tool strays 1.000 mm"),
              "motion: path-deviation on 'G3' lines");
    EXPECT_EQ(finding_root_cause("motion: move-end-missed at 5.6 s (cycle 1): line 1 'N5 G01 X65536 Y1 F5': every line"),
              "motion: move-end-missed on 'G1' lines");
    EXPECT_EQ(finding_root_cause("timeout: line 2 'M104 S200' got no answer within 2 s"), "timeout on 'M104' lines");
}

TEST(FuzzRootCauses, AxisWordsAndCodesNoFirmwareHasAreNotCommands) {
    // An axis word's number is an argument (grbl_stepper takes "X<steps>"),
    // and a G or M number of five digits or more is no code: one shape each.
    EXPECT_EQ(finding_root_cause("timeout: line 3 'X65090 Y1' got no answer within 2 s"), "timeout on 'X' lines");
    EXPECT_EQ(finding_root_cause("timeout: line 3 'X2147483648' got no answer within 2 s"), "timeout on 'X' lines");
    EXPECT_EQ(finding_root_cause("timeout: line 3 'G69661 X1' got no answer within 2 s"), "timeout on 'G' lines");
    EXPECT_EQ(finding_root_cause("timeout: line 3 'G65536' got no answer within 2 s"), "timeout on 'G' lines");
    EXPECT_EQ(finding_root_cause("timeout: line 3 'M7219 S1' got no answer within 2 s"), "timeout on 'M7219' lines");
    EXPECT_EQ(finding_root_cause("timeout: line 3 '5' got no answer within 2 s"), "timeout on 'no command' lines");
}

}  // namespace
}  // namespace avrbench
