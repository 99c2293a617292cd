// An interrupt raised while SEI executes is served after the instruction that
// follows SEI, and stays servable: firmware/conformance/peripherals/
// irq_sei_raise. ATmega328P §7.7 / ATmega2560 §7.8 / ATmega32 "Interrupt
// Response Time": "the instruction following SEI will be executed before any
// pending interrupts"; a pending enabled interrupt is served once I is one
// and that instruction has completed.
#include <gtest/gtest.h>

#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

void expect_every_attempt_served(const std::string& firmware) {
    Mcu mcu(ElfImage::load(test::firmware(firmware)));
    mcu.run_for(40000);  // 24 attempts of about 200 cycles
    ASSERT_EQ(mcu.read_ram_u8("done"), 1) << firmware;
    const auto served = mcu.read_ram("served", 24);
    const auto window = mcu.read_ram("window", 24);
    unsigned previous_window = 3;
    bool saw_window1 = false, saw_later = false;
    for (unsigned k = 0; k < 24; ++k) {
        const unsigned runs = served[k];
        const unsigned w = window[k];
        EXPECT_EQ(runs, 1u) << firmware << ": attempt " << k << " (ISR runs; 0 = a pending interrupt never served)";
        EXPECT_GE(w, 1u) << firmware << " attempt " << k;
        EXPECT_LE(w, previous_window) << firmware << " attempt " << k << ": served in a later window than attempt " << k - 1;
        previous_window = w;
        saw_window1 = saw_window1 || w == 1;
        saw_later = saw_later || w > 1;
    }
    // The sweep covers both sides: matches before and after the first window.
    EXPECT_TRUE(saw_window1 && saw_later) << firmware;
}

TEST(IrqSeiRaise, RaisedDuringSeiIsServedAtmega328p) { expect_every_attempt_served("irq_sei_raise"); }
TEST(IrqSeiRaise, RaisedDuringSeiIsServedAtmega2560) { expect_every_attempt_served("irq_sei_raise_m2560"); }
TEST(IrqSeiRaise, RaisedDuringSeiIsServedAtmega32) { expect_every_attempt_served("irq_sei_raise_m32"); }

}  // namespace
}  // namespace avrbench
