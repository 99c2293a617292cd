// INT0/INT1 level and edge modes, their flags, enabling with a flag set, pin
// change interrupts, and writes to PINx (firmware/conformance/peripherals/
// extint_level, extint_edges, pcint, pin_toggle).
#include "conformance_periph/PeriphSupport.hpp"

extern "C" {
#include <sim_avr.h>
}

namespace avrbench {
namespace {

using test::kJmp;
using test::kSbi;
using test::Markers;
using test::Part;

class ExtintLevel : public ::testing::TestWithParam<const Part*> {};

TEST_P(ExtintLevel, HeldLowLevelRetriggersAfterRetiPlusOneInstruction) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("extint_level", part);
    Markers m(mcu);
    mcu.run_for(1000);
    mcu.pin(part.int0_pin).drive(false);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 3));
    // §13.2.3: INTF0 "is always cleared when INT0 is configured as a level interrupt".
    EXPECT_EQ(mcu.read_ram_u8("flags_while_disabled") & part.intf0, 0) << part.name;
    mcu.run_for(2000);
    const auto& isr = m.rises(0);
    ASSERT_GE(isr.size(), 50u) << part.name << ": the level interrupt must keep firing";
    // Back to back: response (4; 2560: 5) + jmp (3) + sbi (2) + cbi (2) +
    // reti (4; 2560: 5) + the main line's rjmp (2).
    const Cycle period = part.response + kJmp + kSbi + kSbi + part.reti + 2;
    for (std::size_t i = 1; i < isr.size(); ++i) ASSERT_EQ(isr[i] - isr[i - 1], period) << part.name << " ISR " << i;
    // Released: no more interrupts (at most the one already entered).
    mcu.pin(part.int0_pin).drive(true);
    mcu.run_for(20);
    const std::size_t after_release = isr.size();
    mcu.run_for(2000);
    EXPECT_EQ(isr.size(), after_release) << part.name;
}

TEST_P(ExtintLevel, LowPinWithTheInterruptDisabledArmsNoPolling) {
    // simavr 1.6 polls a low INT0/INT1 pin every cycle in level mode, enabled
    // or not (and adds one more poller per falling edge): the cost that made a
    // firmware with step pins on PD2/PD3 5.8x slower. Nothing in the
    // datasheet needs work while the pin merely stays low.
    const Part& part = *GetParam();
    Mcu mcu = test::load("extint_level", part);
    Markers m(mcu);
    mcu.run_for(1000);
    const std::size_t before = mcu.cycle_timers_armed();
    for (int i = 0; i < 5; ++i) {  // falling edges, INT0 still disabled
        mcu.pin(part.int0_pin).drive(false);
        mcu.run_for(10);
        mcu.pin(part.int0_pin).drive(true);
        mcu.run_for(10);
    }
    mcu.pin(part.int0_pin).drive(false);
    mcu.run_for(10);
    EXPECT_EQ(mcu.cycle_timers_armed(), before) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, ExtintLevel,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32),
                         test::part_name);

class ExtintEdges : public ::testing::TestWithParam<const Part*> {};

TEST_P(ExtintEdges, FlagsClearByWritingOneAndAreRememberedUntilEnabled) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("extint_edges", part);
    Markers m(mcu);
    Pin& int0 = mcu.pin(part.int0_pin);
    int0.drive(true);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 0));
    mcu.run_for(200);
    int0.drive(false);  // falling edge, INT0 disabled: INTF0 set
    mcu.run_for(2000);
    EXPECT_EQ(mcu.read_ram_u8("flag_set"), 1) << part.name;
    // §13.2.3: "the flag can be cleared by writing a logical one to it".
    EXPECT_EQ(mcu.read_ram_u8("flag_after_clear") & part.intf0, 0) << part.name;
    ASSERT_TRUE(test::run_until_rise(mcu, m, 1));
    mcu.run_for(200);
    int0.drive(true);
    mcu.run_for(500);
    int0.drive(false);  // a new falling edge; the firmware then enables INT0
    mcu.run_for(2000);
    // §7.7: the flag "will be set and remembered until the interrupt is enabled".
    EXPECT_EQ(mcu.read_ram_u8("int0_count"), 1) << part.name;
}

TEST_P(ExtintEdges, AnyChangeFallingAndRisingModesCountTheirEdges) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("extint_edges", part);
    Markers m(mcu);
    Pin& int0 = mcu.pin(part.int0_pin);
    Pin& int1 = mcu.pin(part.int1_pin);
    int0.drive(true);
    int1.drive(true);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 0));
    mcu.run_for(200);
    int0.drive(false);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 1));
    int0.drive(true);
    mcu.run_for(500);
    int0.drive(false);
    for (int step = 0; step < 3; ++step) {
        ASSERT_TRUE(test::run_until_rise(mcu, m, 2 + step)) << part.name << " step " << step;
        bool level = true;
        for (int i = 0; i < 4; ++i) {  // low, high, low, high: 2 falling + 2 rising edges
            mcu.run_for(500);
            level = !level;
            int1.drive(level);
        }
        mcu.run_for(500);
        int0.drive(true);
        mcu.run_for(500);
        int0.drive(false);
    }
    ASSERT_TRUE(test::run_until_rise(mcu, m, 5));
    const auto counts = mcu.read_ram("int1_count", 3);
    // Table 13-2 (ISC11:10): 01 any logical change -> 4; 10 falling -> 2; 11 rising -> 2.
    EXPECT_EQ(counts[0], 4) << part.name;
    EXPECT_EQ(counts[1], 2) << part.name;
    EXPECT_EQ(counts[2], 2) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, ExtintEdges,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32),
                         test::part_name);

class PeriphPinChange : public ::testing::TestWithParam<const Part*> {};

TEST_P(PeriphPinChange, EnabledPinsInputsAndOutputsRaisePcint0) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("pcint", part);
    Markers m(mcu);
    Pin& pb0 = mcu.pin("PB0");
    Pin& pb1 = mcu.pin("PB1");
    pb0.drive(false);
    pb1.drive(false);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 4));
    mcu.run_for(500);
    pb0.drive(true);  // PCIF0 set, PCIE0 off
    mcu.run_for(2000);
    // §13.2.6 (PCIFR): "the flag can be cleared by writing a logical one to it".
    EXPECT_EQ(mcu.read_ram_u8("flag_after_clear") & 0x01, 0) << part.name;
    ASSERT_TRUE(test::run_until_rise(mcu, m, 5));
    mcu.run_for(500);
    pb0.drive(false);  // PCIF0 set again
    mcu.run_for(500);
    pb1.drive(true);  // masked; tells the firmware to enable PCICR
    mcu.run_for(2000);
    // §7.7: remembered until enabled -> one interrupt.
    EXPECT_EQ(mcu.read_ram_u8("count_after_enable"), 1) << part.name;
    ASSERT_TRUE(test::run_until_rise(mcu, m, 6));
    bool l1 = true, l0 = false;
    for (int i = 0; i < 4; ++i) {
        mcu.run_for(1000);
        pb1.drive(l1 = !l1);  // PCMSK0 bit 1 clear: no interrupt
    }
    for (int i = 0; i < 4; ++i) {
        mcu.run_for(1000);
        pb0.drive(l0 = !l0);  // each change of an enabled pin: one interrupt
    }
    ASSERT_TRUE(test::run_until_rise(mcu, m, 7));
    EXPECT_EQ(mcu.read_ram_u8("count_inputs"), 4) << part.name;
    // Outputs too: "the interrupts will trigger even if the ... pins are
    // configured as outputs" (§13).
    EXPECT_EQ(mcu.read_ram_u8("count_outputs"), 2) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, PeriphPinChange, ::testing::Values(&test::kAtmega328p, &test::kAtmega2560),
                         test::part_name);

TEST(PeriphPinToggle, SbiOnPinxTogglesOnlyItsBit) {
    for (const Part* part : {&test::kAtmega328p, &test::kAtmega2560}) {
        Mcu mcu = test::load("pin_toggle", *part);
        mcu.run_for(2000);
        // PORTB = 0x0F; §14.2.2: SBI PINB,4 toggles PORTB4 only -> 0x1F.
        EXPECT_EQ(mcu.read_ram_u8("after_sbi"), 0x1F) << part->name;
        // CBI PINB,0 writes a zero to PINB0 only: no effect.
        EXPECT_EQ(mcu.read_ram_u8("after_cbi"), 0x1F) << part->name;
        // PINB = 0x81 toggles bits 7 and 0: 0x1F ^ 0x81 = 0x9E.
        EXPECT_EQ(mcu.read_ram_u8("after_write"), 0x9E) << part->name;
    }
}

TEST(PeriphPinToggle, Atmega32PinRegistersAreReadOnly) {
    Mcu mcu = test::load("pin_toggle", test::kAtmega32);
    mcu.run_for(2000);
    // ATmega32 datasheet, "Port B Input Pins Address - PINB": read-only bits.
    EXPECT_EQ(mcu.read_ram_u8("after_sbi"), 0x0F);
    EXPECT_EQ(mcu.read_ram_u8("after_cbi"), 0x0F);
    EXPECT_EQ(mcu.read_ram_u8("after_write"), 0x0F);
}

}  // namespace
}  // namespace avrbench
