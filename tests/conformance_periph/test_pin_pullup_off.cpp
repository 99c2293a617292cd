// An input whose pull-up is switched off (PORTxn = 0, or PUD = 1) is no
// longer held high: firmware/conformance/peripherals/pin_pullup_off.
// ATmega328P §14.2.1 and Table 14-1: DDxn = 0 with PORTxn = 0 or PUD = 1 is
// tri-state (Hi-Z); nothing drives PB0 here, so it reads the bench's defined
// level for an undriven input, 0 (docs/FIDELITY.md).
#include <gtest/gtest.h>

#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

void expect_pullup_follows_port_and_pud(const std::string& firmware) {
    Mcu mcu(ElfImage::load(test::firmware(firmware)));
    mcu.run_for(2000);
    ASSERT_EQ(mcu.read_ram_u8("done"), 1) << firmware;
    const auto reads = mcu.read_ram("reads", 5);
    EXPECT_EQ(reads[0], 1) << firmware << ": pull-up on";
    EXPECT_EQ(reads[1], 0) << firmware << ": PORTB0 = 0 switched the pull-up off";
    EXPECT_EQ(reads[2], 0) << firmware << ": an output that drove high, made an input without pull-up";
    EXPECT_EQ(reads[3], 0) << firmware << ": PUD = 1 disables every pull-up";
    EXPECT_EQ(reads[4], 1) << firmware << ": PUD = 0 enables it again";
}

TEST(PinPullupOff, InputFloatsWhenItsPullupIsOffAtmega328p) { expect_pullup_follows_port_and_pud("pin_pullup_off"); }
TEST(PinPullupOff, InputFloatsWhenItsPullupIsOffAtmega2560) { expect_pullup_follows_port_and_pud("pin_pullup_off_m2560"); }
TEST(PinPullupOff, InputFloatsWhenItsPullupIsOffAtmega32) { expect_pullup_follows_port_and_pud("pin_pullup_off_m32"); }

}  // namespace
}  // namespace avrbench
