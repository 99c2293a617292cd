// EEPROM read/write timing and EE_READY (firmware/conformance/peripherals/eeprom_timing).
#include "conformance_periph/PeriphSupport.hpp"

namespace avrbench {
namespace {

using test::kJmp;
using test::kSbi;
using test::Markers;
using test::Part;

// Erase-and-write programming time at 16 MHz: 3.4 ms (328P §8.6.3 Table 8-2,
// 2560 Table 8-1) = 54400 cycles; ATmega32 ("EEPROM Data Memory" Table 1):
// 8448 cycles of the 1 MHz calibrated RC oscillator = 8.448 ms = 135168 cycles.
Cycle write_cycles(const Part& part) { return std::string(part.mcu) == "atmega32" ? 135168 : 54400; }

class EepromTiming : public ::testing::TestWithParam<const Part*> {};

TEST_P(EepromTiming, ReadHaltsTheCpuFourCyclesAndReadsTheEepromSection) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("eeprom_timing", part);
    Markers m(mcu);
    mcu.run_for(2000);
    // sbi PORTB,0 (2) ; sbi EECR,EERE (2 + 4 halted) ; sbi PORTB,1.
    EXPECT_EQ(m.rise(1) - m.rise(0), kSbi + kSbi + 4) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("read_value"), 0x5A) << part.name;
}

TEST_P(EepromTiming, EepeStaysSetForTheProgrammingTime) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("eeprom_timing", part);
    Markers m(mcu);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 4, 400000));
    // sbi PORTB,2 (2) ; sbi EECR,EEMPE (2) ; sbi EECR,EEPE (2 + 2 halted) ; sbi PORTB,3.
    EXPECT_EQ(m.rise(3) - m.rise(2), 4 * kSbi) << part.name;
    // EEPE is written 4 cycles after the PB2 marker and stays set for the
    // programming time; the sbic/rjmp loop (3 cycles a turn) then falls through
    // (sbic skipping the 1-word rjmp: 2 cycles) to the sbi.
    const Cycle eepe = m.rise(2) + 2 * kSbi;
    EXPECT_GE(m.rise(4) - eepe, write_cycles(part)) << part.name;
    EXPECT_LE(m.rise(4) - eepe, write_cycles(part) + 6) << part.name;
    mcu.run_for(400000);
    EXPECT_EQ(mcu.read_ram_u8("value6"), 0xA5) << part.name;
}

TEST_P(EepromTiming, EepromReadyIsALevelInterruptWhileEepeIsClear) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("eeprom_timing", part);
    Markers m(mcu);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 6, 800000));
    // Enabled with no write in progress: "a constant interrupt when EEPE is cleared".
    EXPECT_EQ(mcu.read_ram_u8("count_idle"), 1) << part.name;
    mcu.run_for(200000);
    // The write started by `sbi EECR,EEPE` 4 cycles after the PB6 marker ends
    // after the programming time; the interrupt wakes the sleeping core:
    // wake-up + response + jmp, then the ISR's sbi (§7.7.1).
    ASSERT_EQ(m.rises(5).size(), 2u) << part.name;
    const Cycle eepe = m.rise(6) + 2 * kSbi;
    EXPECT_EQ(m.rise(5, 1) - eepe, write_cycles(part) + part.response + part.response + kJmp) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, EepromTiming,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32), test::part_name);

TEST(EepromModes, WriteOnlyAndEraseOnlyModes) {
    for (const Part* part : {&test::kAtmega328p, &test::kAtmega2560}) {
        Mcu mcu = test::load("eeprom_timing", *part);
        mcu.run_for(600000);
        // Table 8-2: EEPM = 10 write only (bits can only be cleared): 0x5A & 0x0F;
        // EEPM = 01 erase only: 0xFF.
        EXPECT_EQ(mcu.read_ram_u8("value5"), 0x5A & 0x0F) << part->name;
        EXPECT_EQ(mcu.read_ram_u8("value7"), 0xFF) << part->name;
    }
}

}  // namespace
}  // namespace avrbench
