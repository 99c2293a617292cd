// Interrupt response time, one instruction after SEI/RETI, nested interrupts
// (firmware/conformance/peripherals/irq_latency, built as irq_latency* and
// irq_nested*). Marker edges carry the cycle at which the writing instruction
// starts, so the distance between two markers is the sum of the cycles of
// everything executed in between.
#include "conformance_periph/PeriphSupport.hpp"

namespace avrbench {
namespace {

using test::kJmp;
using test::kSbi;
using test::Markers;
using test::Part;

class InterruptLatency : public ::testing::TestWithParam<const Part*> {};

TEST_P(InterruptLatency, ResponseIsFourCyclesPlusJmpAfterTheInstructionFollowingSei) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("irq_latency", part);
    Markers m(mcu);
    mcu.run_for(20000);
    // sbi PORTB,0 (2) ; sei (1) ; inc r24 (1: "the instruction following SEI
    // will be executed before any pending interrupts") ; response (4, 2560: 5)
    // ; jmp (3) ; then the ISR's sbi PORTB,1.
    EXPECT_EQ(m.rise(1) - m.rise(0), kSbi + 1 + 1 + part.response + kJmp) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("int0_seen"), 1) << part.name << ": main-line instructions run before INT0";
}

TEST_P(InterruptLatency, RetiRunsOneMoreInstructionBeforeThePendingInterrupt) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("irq_latency", part);
    Markers m(mcu);
    mcu.run_for(20000);
    // INT0's cbi PORTB,1 (2) ; reti (4, 2560: 5) ; one main-line inc (1) ;
    // response (4/5) ; jmp (3) ; INT1's sbi PORTB,2.
    EXPECT_EQ(m.rise(2) - m.fall(1), kSbi + part.reti + 1 + part.response + kJmp) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("int1_seen"), 2) << part.name << ": one inc after SEI, one after RETI";
    EXPECT_EQ(mcu.read_ram_u8("main_count"), 6) << part.name;
}

TEST_P(InterruptLatency, SeiInsideAnIsrLetsAPendingInterruptNest) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("irq_nested", part);
    Markers m(mcu);
    mcu.run_for(20000);
    // INT0 (ISR_NOBLOCK style): sbi PORTB,1 (2) ; sei (1) ; inc (1) ; then
    // INT1 nests: response + jmp ; sbi PORTB,2.
    EXPECT_EQ(m.rise(2) - m.rise(1), kSbi + 1 + 1 + part.response + kJmp) << part.name;
    // Nested order: INT0 starts, INT1 starts and ends, INT0 ends.
    EXPECT_LT(m.rise(1), m.rise(2));
    EXPECT_LT(m.fall(2), m.fall(1));
    EXPECT_EQ(mcu.read_ram_u8("int1_seen"), 2) << part.name << ": one main inc, one INT0 inc";
    EXPECT_EQ(mcu.read_ram_u8("int0_seen"), 4) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("main_count"), 9) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, InterruptLatency,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32),
                         test::part_name);

}  // namespace
}  // namespace avrbench
