// SPI master timing and write collision (firmware/conformance/peripherals/
// spi_timing): a byte takes 8 SCK periods, SCK = f_osc/4, 16, 64, 128 by
// SPR1:0 and twice as fast with SPI2X (ATmega328P §19.5 Table 19-5,
// ATmega2560 §21.2 Table 21-5); SPDR written during a transfer sets WCOL
// (328P §19.5.2, 2560 §21.2.2).
#include "conformance_periph/PeriphSupport.hpp"

namespace avrbench {
namespace {

using test::Part;

class SpiTiming : public ::testing::TestWithParam<const Part*> {};

TEST_P(SpiTiming, AByteTakesEightSckPeriods) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("spi_timing", part);
    mcu.run_for(200000);
    ASSERT_EQ(mcu.read_ram_u8("done"), 1) << part.name;
    const auto c = mcu.read_ram("cycles", 10);
    const auto at = [&](int i) { return static_cast<int>(c[2 * i] | (c[2 * i + 1] << 8)); };
    // The poll loop's own cycles are the same in each measurement: the
    // differences are 8 SCK periods: 8 * (16 - 4), 8 * (64 - 16), 8 * (128 - 64),
    // and SPI2X at f/4 gives f/2: 8 * (2 - 4).
    EXPECT_EQ(at(1) - at(0), 96) << part.name;
    EXPECT_EQ(at(2) - at(1), 384) << part.name;
    EXPECT_EQ(at(3) - at(2), 512) << part.name;
    EXPECT_EQ(at(4) - at(0), -16) << part.name;
    // f/4: 32 cycles of transfer, plus the loop (a few cycles at most).
    EXPECT_GE(at(0), 32) << part.name;
    EXPECT_LE(at(0), 32 + 12) << part.name;
}

TEST_P(SpiTiming, WritingSpdrDuringATransferSetsWcol) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("spi_timing", part);
    mcu.run_for(200000);
    ASSERT_EQ(mcu.read_ram_u8("done"), 1) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("wcol_spsr") & 0x40, 0x40) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, SpiTiming, ::testing::Values(&test::kAtmega328p, &test::kAtmega2560), test::part_name);

// The master's SS pin (328P §19.3.2, 2560 §21.3.2; firmware/conformance/
// peripherals/spi_slave_select): as an input it must stay high; driven low
// it makes the SPI a slave (MSTR cleared) and sets SPIF, with the interrupt
// if enabled; as an output it does not matter.
class SpiSlaveSelect : public ::testing::TestWithParam<const Part*> {};

constexpr std::uint8_t kSpif = 0x80, kMstr = 0x10, kSpe = 0x40, kSpie = 0x80;

bool run_until_stage(Mcu& mcu, std::uint8_t stage) {
    for (int i = 0; i < 4000 && mcu.read_ram_u8("stage") < stage; ++i) mcu.run_for(50);
    return mcu.read_ram_u8("stage") >= stage;
}

TEST_P(SpiSlaveSelect, AnInputSsDrivenLowMakesTheMasterASlave) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("spi_slave_select", part);
    Pin& ss = mcu.pin(std::string(part.mcu) == "atmega2560" ? "PB0" : "PB2");  // SS: 2560 Table 13-6, 328P Table 14-3
    ASSERT_TRUE(run_until_stage(mcu, 2)) << part.name;
    // Held high by its pull-up, or an output (even low): the byte goes out, still master.
    EXPECT_EQ(mcu.read_ram_u8("spsr_input_high") & kSpif, kSpif) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("spcr_input_high"), kSpe | kMstr) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("spsr_output_low") & kSpif, kSpif) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("spcr_output_low"), kSpe | kMstr) << part.name;

    ss.drive(true);
    ASSERT_TRUE(run_until_stage(mcu, 3)) << part.name;
    mcu.run_for(500);
    ss.drive(false);
    ASSERT_TRUE(run_until_stage(mcu, 4)) << part.name;
    // "The MSTR bit in SPCR is cleared ... The SPIF Flag in SPSR is set".
    EXPECT_EQ(mcu.read_ram_u8("spcr_driven_low"), kSpe) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("spsr_driven_low") & kSpif, kSpif) << part.name;

    ss.drive(true);
    ASSERT_TRUE(run_until_stage(mcu, 5)) << part.name;
    mcu.run_for(500);
    ss.drive(false);
    mcu.run_for(20000);
    ASSERT_EQ(mcu.read_ram_u8("done"), 1) << part.name;
    // "... and if the SPI interrupt is enabled, and the I-bit in SREG is set,
    // the interrupt routine will be executed": once, MSTR already cleared.
    EXPECT_EQ(mcu.read_ram_u8("isr_count"), 1) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("spcr_in_isr"), kSpe | kSpie) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("spcr_after_isr"), kSpe | kSpie) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, SpiSlaveSelect, ::testing::Values(&test::kAtmega328p, &test::kAtmega2560), test::part_name);

}  // namespace
}  // namespace avrbench
