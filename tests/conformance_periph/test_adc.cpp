// ADC conversion timing, channel latching, auto-trigger sources
// (firmware/conformance/peripherals/adc_modes) and the ADC8..15 inputs.
#include <vector>

extern "C" {
#include <avr_adc.h>
#include <avr_timer.h>
#include <sim_avr.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include "conformance_periph/PeriphSupport.hpp"
#include "periph/adc/Adc.hpp"
#include "periph/Fix.hpp"

namespace avrbench {
namespace {

using test::Markers;
using test::Part;

// ADPS2:0 = 100: division factor 16 (328P §24.9.2 Table 24-5).
constexpr Cycle kAdcClock = 16;

// Timestamps of interrupt flags being set (a vector's "pending" IRQ, raised
// when simavr sets the flag) and of ADSC writes.
struct AdcProbe {
    std::vector<Cycle> adif, trigger_t1b, trigger_t0ovf, adsc_writes;
    std::unique_ptr<IoWriteHook> adcsra_hook;

    static void on_pending(avr_irq_t*, std::uint32_t value, void* param) {
        auto* v = static_cast<std::pair<avr_t*, std::vector<Cycle>*>*>(param);
        if (value != 0) v->second->push_back(v->first->cycle);
    }
    std::vector<std::unique_ptr<std::pair<avr_t*, std::vector<Cycle>*>>> params;
    void watch(avr_t* avr, avr_int_vector_t& vec, std::vector<Cycle>& into) {
        params.push_back(std::make_unique<std::pair<avr_t*, std::vector<Cycle>*>>(avr, &into));
        avr_irq_register_notify(vec.irq + AVR_INT_IRQ_PENDING, &on_pending, params.back().get());
    }

    explicit AdcProbe(Mcu& mcu) {
        auto* adc = reinterpret_cast<avr_adc_t*>(mcu.io_module("adc"));
        avr_t* avr = adc->io.avr;
        watch(avr, adc->adc, adif);
        auto* t1 = reinterpret_cast<avr_timer_t*>(mcu.io_module("timer", '1'));
        watch(avr, t1->comp[AVR_TIMER_COMPB].interrupt, trigger_t1b);
        auto* t0 = reinterpret_cast<avr_timer_t*>(mcu.io_module("timer", '0'));
        watch(avr, t0->overflow, trigger_t0ovf);
        adcsra_hook = std::make_unique<IoWriteHook>(
            avr, adc->r_adcsra,
            [](IoWriteHook& hook, avr_t* a, avr_io_addr_t addr, std::uint8_t value) {
                auto* self = static_cast<AdcProbe*>(hook.context());
                if (value & (1 << 6)) self->adsc_writes.push_back(a->cycle);  // ADSC is bit 6 on all three
                hook.write_original(a, addr, value);
            },
            this);
    }
};

// Input voltages (AVCC = 5 V reference): ADC = VIN * 1024 / VREF (§24.7).
void feed(Mcu& mcu) {
    const double volts[8] = {0.3125, 1.25, 2.5, 0.625, 3.75, 1.875, 4.375, 3.125};
    for (int ch = 0; ch < 8; ++ch) mcu.adc().set_voltage(ch, volts[ch]);
}
// The codes of those voltages: V * 1024 / 5.
constexpr std::uint16_t kCode[8] = {64, 256, 512, 128, 768, 384, 896, 640};

std::uint16_t result(Mcu& mcu, int i) {
    const auto d = mcu.read_ram("results", 2 * static_cast<std::size_t>(i) + 2);
    return static_cast<std::uint16_t>(d[2 * i] | (d[2 * i + 1] << 8));
}

class AdcModes : public ::testing::TestWithParam<const Part*> {};

TEST_P(AdcModes, SingleConversionsEndOnTheAdcClockGrid) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("adc_modes", part);
    feed(mcu);
    AdcProbe probe(mcu);
    mcu.run_for(3000);
    ASSERT_GE(probe.adif.size(), 2u);
    ASSERT_GE(probe.adsc_writes.size(), 2u);
    // §24.4: the first conversion after ADEN takes 25 ADC clocks, a normal one
    // 13, each starting "at the following rising edge of the ADC clock"
    // (0..1 clock after ADSC is written).
    const Cycle first = probe.adif[0] - probe.adsc_writes[0];
    EXPECT_GE(first, 25 * kAdcClock) << part.name;
    EXPECT_LE(first, 26 * kAdcClock) << part.name;
    const Cycle single = probe.adif[1] - probe.adsc_writes[1];
    EXPECT_GE(single, 13 * kAdcClock) << part.name;
    EXPECT_LE(single, 14 * kAdcClock) << part.name;
    // The prescaler runs from ADEN, so both conversions start and end on the
    // same ADC clock edges: their ends are a whole number of clocks apart.
    EXPECT_EQ((probe.adif[1] - probe.adif[0]) % kAdcClock, 0u) << part.name;
    EXPECT_EQ(result(mcu, 0), kCode[1]) << part.name;
    EXPECT_EQ(result(mcu, 1), kCode[2]) << part.name;
}

TEST_P(AdcModes, FreeRunningIsThirteenClocksAndLagsAChannelChangeByOneResult) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("adc_modes", part);
    feed(mcu);
    AdcProbe probe(mcu);
    mcu.run_for(6000);
    ASSERT_GE(probe.adif.size(), 6u);
    // §24.4: "a new conversion will be started immediately after the
    // conversion completes": 13 ADC clocks apart.
    for (int i = 3; i < 6; ++i) EXPECT_EQ(probe.adif[i] - probe.adif[i - 1], 13 * kAdcClock) << part.name << " " << i;
    // §24.5: after a change "the next result will reflect the previous channel
    // selection. Subsequent conversions will reflect the new channel selection."
    EXPECT_EQ(result(mcu, 2), kCode[3]) << part.name;
    EXPECT_EQ(result(mcu, 3), kCode[3]) << part.name;
    EXPECT_EQ(result(mcu, 4), kCode[4]) << part.name;
    EXPECT_EQ(result(mcu, 5), kCode[4]) << part.name;
}

TEST_P(AdcModes, TimerCompareAndOverflowTriggersStartConversions) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("adc_modes", part);
    feed(mcu);
    AdcProbe probe(mcu);
    Markers m(mcu);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 0, 400000));
    // Phase D: Timer1 compare match B, the ISR clears OCF1B: three results of channel 5.
    for (int i = 6; i < 9; ++i) EXPECT_EQ(result(mcu, i), kCode[5]) << part.name << " " << i;
    // Table 24-1: an auto-triggered conversion ends 13.5 ADC clocks after the
    // trigger (+ up to 3 CPU cycles of synchronisation, §24.4).
    int checked = 0;
    for (Cycle t : probe.trigger_t1b) {
        auto end = std::lower_bound(probe.adif.begin(), probe.adif.end(), t);
        if (end == probe.adif.end() || *end - t > 1000) continue;
        EXPECT_GE(*end - t, kAdcClock * 27 / 2) << part.name;
        EXPECT_LE(*end - t, kAdcClock * 27 / 2 + 3) << part.name;
        ++checked;
    }
    EXPECT_GE(checked, 3) << part.name;
    // Phase E: OCF1B left set: "the Interrupt Flag must be cleared in order to
    // trigger a new conversion" -> exactly one.
    EXPECT_EQ(mcu.read_ram_u8("count_no_clear"), 1) << part.name;
    // Phase F: Timer0 overflow (its ISR clears TOV0): two results of channel 6.
    EXPECT_EQ(result(mcu, 9), kCode[6]) << part.name;
    EXPECT_EQ(result(mcu, 10), kCode[6]) << part.name;
    // Phase H: Timer0 compare match (A) (seed 001's trigger on the ATmega32).
    EXPECT_EQ(result(mcu, 11), kCode[0]) << part.name;
    EXPECT_EQ(result(mcu, 12), kCode[0]) << part.name;
}

TEST_P(AdcModes, ExternalInterruptZeroTriggersAConversionPerEdge) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("adc_modes", part);
    feed(mcu);
    Markers m(mcu);
    Pin& int0 = mcu.pin(part.int0_pin);
    int0.drive(true);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 0, 400000));
    for (int i = 0; i < 2; ++i) {
        mcu.run_for(1000);
        int0.drive(false);
        mcu.run_for(1000);
        int0.drive(true);
    }
    ASSERT_TRUE(test::run_until_rise(mcu, m, 1, 10000)) << part.name;
    EXPECT_EQ(result(mcu, 13), kCode[7]) << part.name;
    EXPECT_EQ(result(mcu, 14), kCode[7]) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, AdcModes,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32), test::part_name);

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

class AdcFlags : public ::testing::TestWithParam<const test::Part*> {};

TEST_P(AdcFlags, AdifClearsOnOneIsRememberedForAdieAndAdclReadLocksTheResult) {
    const test::Part& part = *GetParam();
    Mcu mcu = test::load("adc_flags", part);
    test::Markers m(mcu);
    mcu.adc().set_voltage(1, 1.25);  // 1.25 * 1024 / 5 = 256 = 0x100
    ASSERT_TRUE(test::run_until_rise(mcu, m, 0, 100000));
    mcu.adc().set_voltage(1, 3.75);  // 768 = 0x300
    mcu.run_for(20000);
    EXPECT_EQ(mcu.read_ram_u16("first"), 256) << part.name;
    // §24.9.2: "ADIF is cleared by writing a logical one to the flag" (bit 4).
    EXPECT_EQ(mcu.read_ram_u8("adcsra_after_clear") & 0x10, 0) << part.name;
    // §24.2: after the ADCL read the next conversion's result is lost: ADCH
    // still holds the locked result's high byte (768 >> 8 = 3), and so does
    // the following read of both.
    EXPECT_EQ(mcu.read_ram_u8("low_locked"), 768 & 0xFF) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("high_locked"), 768 >> 8) << part.name;
    EXPECT_EQ(mcu.read_ram_u16("after_lock"), 768) << part.name;
    // §7.7: ADIF set while ADIE was off: enabling ADIE interrupts once.
    EXPECT_EQ(mcu.read_ram_u8("isr_count"), 1) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, AdcFlags,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32), test::part_name);

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

class AdcSleep : public ::testing::TestWithParam<const test::Part*> {};

TEST_P(AdcSleep, AdcNoiseReductionModeStartsAConversionThatWakesThePart) {
    const test::Part& part = *GetParam();
    Mcu mcu = test::load("adc_sleep", part);
    test::Markers m(mcu);
    mcu.adc().set_voltage(2, 2.5);  // 2.5 * 1024 / 5 = 512
    mcu.run_for(5000);
    ASSERT_EQ(m.rises(1).size(), 1u) << part.name << ": entering ADC Noise Reduction mode started no conversion";
    EXPECT_EQ(mcu.read_ram_u16("result"), 512) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("woke"), 1) << part.name;
    // sbi (2) + sleep (1); the conversion starts at the next ADC clock edge
    // (0..1 clock of 16 cycles) and takes 13 clocks (§24.4); then wake-up (4;
    // 2560: 5) + response (4; 5) + jmp (3) and the ISR's sbi.
    const Cycle base = test::kSbi + 1 + 13 * kAdcClock + part.response + part.response + test::kJmp;
    EXPECT_GE(m.rise(1) - m.rise(0), base) << part.name;
    EXPECT_LE(m.rise(1) - m.rise(0), base + kAdcClock) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, AdcSleep,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32), test::part_name);

}  // namespace
}  // namespace avrbench
