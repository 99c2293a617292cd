// SLEEP and wake-up (firmware/conformance/peripherals/sleep_wake) and the
// watchdog's interrupt modes (watchdog_modes, watchdog_int_reset).
#include <algorithm>

#include "conformance_periph/PeriphSupport.hpp"
#include "mcu/TimingProfile.hpp"

namespace avrbench {
namespace {

using test::kJmp;
using test::kSbi;
using test::Markers;
using test::Part;

// The ELF's .fuse section: low fuse 0xFF = low-power crystal, CKSEL0 = 1,
// SUT1:0 = 11: start-up from Power-down 16K CK (328P §9.2 Table 9-4; same
// table in the 2560 and m32 datasheets).
constexpr Cycle kPowerDownStartup = 16 * 1024;

class SleepWake : public ::testing::TestWithParam<const Part*> {};

TEST_P(SleepWake, SleepWithSeClearIsANop) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("sleep_wake", part);
    Markers m(mcu);
    mcu.run_for(2000);
    // sbi PORTB,0 (2) ; sleep (1, SE = 0: §10.1 needs SE = 1 to sleep) ; cbi PORTB,0.
    EXPECT_EQ(m.fall(0) - m.rise(0), kSbi + 1) << part.name;
    EXPECT_FALSE(mcu.halted()) << part.name << ": " << mcu.halt_reason();
}

TEST_P(SleepWake, PendingInterruptIsServedBeforeTheInstructionAfterSeiSleep) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("sleep_wake", part);
    Markers m(mcu);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 1));
    // `sei ; sleep ; inc r24`: the instruction after SEI (SLEEP) runs first,
    // the part sleeps and the pending INT1 wakes it at once; its ISR sees r24 = 0.
    EXPECT_EQ(mcu.read_ram_u8("pending_result"), 0) << part.name;
}

TEST_P(SleepWake, IdleWakeUpAddsTheResponseTimeAgain) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("sleep_wake", part);
    Markers m(mcu);
    Pin& int0 = mcu.pin(part.int0_pin);
    int0.drive(true);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 1));
    const Cycle event = mcu.cycle() + 1000;  // the firmware sleeps (Idle) long before
    mcu.scheduler().at(event, [&](Cycle) { int0.drive(false); });
    ASSERT_TRUE(test::run_until_rise(mcu, m, 2));
    // §7.7.1: sleep adds 4 cycles (2560: 5) to the response; Idle has no
    // start-up time (the clock runs); then the JMP; then the ISR's sbi.
    EXPECT_EQ(m.rise(2) - event, part.response + 0 + part.response + kJmp) << part.name;
}

// The timing profile sees the same wake-up: INT0 (vector 1) from the edge
// to the vector's first instruction (its JMP) is the response time twice
// (§7.7.1: 4 + 4 cycles; the 2560's 5 + 5).
TEST_P(SleepWake, TheProfilesLatencyOfAWakeUpIsTheResponseTwice) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("sleep_wake", part);
    mcu.enable_profile();
    Markers m(mcu);
    Pin& int0 = mcu.pin(part.int0_pin);
    int0.drive(true);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 1));
    const Cycle event = mcu.cycle() + 1000;
    mcu.scheduler().at(event, [&](Cycle) { int0.drive(false); });
    ASSERT_TRUE(test::run_until_rise(mcu, m, 2));
    const auto& vectors = mcu.profile()->vectors();
    ASSERT_EQ(vectors.count(1), 1u) << part.name;
    const VectorProfile& int0_vector = vectors.at(1);
    ASSERT_EQ(int0_vector.latency_cycles.count(), 1u) << part.name;
    EXPECT_EQ(int0_vector.latency_cycles.max(), static_cast<Cycle>(2 * part.response)) << part.name;
    // The Idle sleep before it counts as asleep, not executing.
    EXPECT_GE(mcu.profile()->sleeping_cycles(), 1000u - 50) << part.name;
}

TEST_P(SleepWake, PowerDownWakesOnLevelAfterTheStartUpTime) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("sleep_wake", part);
    Markers m(mcu);
    Pin& int0 = mcu.pin(part.int0_pin);
    Pin& int1 = mcu.pin(part.int1_pin);
    int0.drive(true);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 1));
    mcu.scheduler().at(mcu.cycle() + 1000, [&](Cycle) { int0.drive(false); });
    ASSERT_TRUE(test::run_until_rise(mcu, m, 2));
    mcu.run_for(2000);
    int0.drive(true);  // step 4: the firmware goes to Power-down
    ASSERT_TRUE(test::run_until_rise(mcu, m, 3));
    const Cycle edge = mcu.cycle() + 1000;
    const Cycle level = edge + 50000;
    mcu.scheduler().at(edge, [&](Cycle) { int0.drive(false); });
    mcu.scheduler().at(level, [&](Cycle) { int1.drive(false); });
    mcu.run_until(level + 40000);
    // Waking from Power-down: 4 cycles (2560: 5) + the start-up time + response + JMP.
    const Cycle wake = part.response + kPowerDownStartup + part.response + kJmp;
    if (part.int0_edge_wakes_power_down) {
        // 2560 §15: INT3:0 are asynchronous; the edge wakes the part.
        EXPECT_EQ(m.rise(2, 1) - edge, wake) << part.name;
    } else {
        // Table 10-1 note 3: from Power-down INT0/INT1 wake on level only.
        EXPECT_EQ(m.rises(2).size(), 1u) << part.name << ": an INT0 edge woke the part from Power-down";
        EXPECT_EQ(m.rise(5, 1) - level, wake) << part.name;
        EXPECT_EQ(mcu.read_ram_u8("wakeups"), 2) << part.name;
    }
}

INSTANTIATE_TEST_SUITE_P(Parts, SleepWake,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32),
                         test::part_name);

// WDP3:0 = 0000: 2K cycles of the 128 kHz watchdog oscillator (328P §11.9.2
// Table 11-2, 2560 Table 12-2: 16 ms) = 2048 * 16e6 / 128e3 cycles.
constexpr Cycle kWatchdogPeriod = Cycle{2048} * 16'000'000 / 128'000;  // 256000

class WatchdogModes : public ::testing::TestWithParam<const Part*> {};

TEST_P(WatchdogModes, InterruptModeInterruptsAtEveryTimeOut) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("watchdog_modes", part);
    Markers m(mcu);
    mcu.run_until(7 * kWatchdogPeriod + kWatchdogPeriod / 2);
    // Table 11-1: WDE = 0, WDIE = 1 is Interrupt Mode; WDIE is cleared by
    // hardware only in Interrupt and System Reset Mode.
    EXPECT_EQ(mcu.read_ram_u8("wdt_interrupts"), 7) << part.name;
    EXPECT_EQ(mcu.resets(), 0u) << part.name;
    std::vector<Cycle> edges = m.rises(0);
    edges.insert(edges.end(), m.falls(0).begin(), m.falls(0).end());
    std::sort(edges.begin(), edges.end());
    ASSERT_GE(edges.size(), 6u);
    for (std::size_t i = 1; i < edges.size(); ++i) {
        // One time-out apart; the interrupt waits for the main loop's 2-cycle
        // rjmp to finish (§7.7.1), so +-1.
        EXPECT_NEAR(static_cast<double>(edges[i] - edges[i - 1]), static_cast<double>(kWatchdogPeriod), 1.0)
            << part.name;
    }
}

TEST_P(WatchdogModes, InterruptAndResetModeInterruptsThenResetsAndPinsTriState) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("watchdog_int_reset", part);
    Markers m(mcu, "PB");
    mcu.run_until(3 * kWatchdogPeriod);
    // First time-out: the interrupt (WDIE then cleared by hardware); second: a reset.
    EXPECT_EQ(mcu.read_ram_u8("boot_count"), 2) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("reset_flags"), 0x08) << part.name;  // MCUSR.WDRF (§11.9.1)
    EXPECT_EQ(mcu.resets(), 1u) << part.name;
    EXPECT_EQ(m.rises(0).size(), 1u) << part.name << ": one watchdog interrupt";
    // §11.1: "The I/O ports of the AVR are immediately reset to their initial
    // state when a reset source goes active" (inputs, no pull-up): PB5 falls
    // at the reset itself (not when the new boot rewrites DDRB), two time-outs
    // after the watchdog was enabled, and rises again when the new boot drives it.
    // The firmware set the watchdog up and spins without WDR: a reset it
    // asked for (periph/watchdog/WatchdogWatch.hpp), not a finding.
    EXPECT_TRUE(mcu.findings().empty()) << part.name;
    ASSERT_EQ(mcu.requested_resets().size(), 1u) << part.name;
    const Cycle reset_cycle = mcu.requested_resets()[0].cycle;
    EXPECT_GE(reset_cycle, 2 * kWatchdogPeriod) << part.name;
    EXPECT_LE(reset_cycle, 2 * kWatchdogPeriod + 1000) << part.name;
    ASSERT_EQ(m.falls(5).size(), 1u) << part.name;
    EXPECT_EQ(m.fall(5), reset_cycle) << part.name;
    ASSERT_EQ(m.rises(5).size(), 2u) << part.name;
    EXPECT_GT(m.rise(5, 1), m.fall(5)) << part.name;
}

TEST_P(WatchdogModes, ANewPrescalerTakesEffectAtTheNextTimeOut) {
    // watchdog_prescaler: 500 ms served ten times 16000 cycles apart, then
    // WDR and WDP = 0000 (16 ms): the reset 16 ms after that (328P §11.9.2,
    // 2560 §12.5.2), where simavr 1.6 keeps the 500 ms period (64K cycles of
    // 128 kHz = 512 ms) until the next enable.
    const Part& part = *GetParam();
    Mcu mcu = test::load("watchdog_prescaler", part);
    mcu.run_until(30 * 16000 + kWatchdogPeriod);
    EXPECT_EQ(mcu.read_ram_u8("boot_count"), 2) << part.name;
    EXPECT_EQ(mcu.read_ram_u8("reset_flags"), 0x08) << part.name;  // WDRF
    ASSERT_EQ(mcu.requested_resets().size(), 1u) << part.name;
    const Cycle served = 10 * 16000;
    EXPECT_GE(mcu.requested_resets()[0].cycle, served + kWatchdogPeriod) << part.name;
    EXPECT_LE(mcu.requested_resets()[0].cycle, served + kWatchdogPeriod + 2000) << part.name;
}

INSTANTIATE_TEST_SUITE_P(Parts, WatchdogModes, ::testing::Values(&test::kAtmega328p, &test::kAtmega2560),
                         test::part_name);

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(WatchdogAtmega32, ResetsAfterSixteenKCyclesOfTheOneMegahertzOscillatorThenStaysOff) {
    Mcu mcu(ElfImage::load(test::firmware("watchdog_m32")));
    // ATmega32 Table 17: WDP2:0 = 000 -> 16K cycles of the 1 MHz watchdog
    // oscillator = 16384 us = 262144 cycles at 16 MHz.
    constexpr Cycle kPeriod = Cycle{16384} * 16;
    mcu.run_until(12 * kPeriod);
    // Enabled within the first 1000 cycles of boot 1, then a spin without
    // WDR: a reset the firmware asked for (periph/watchdog/WatchdogWatch.hpp).
    EXPECT_TRUE(mcu.findings().empty());
    ASSERT_EQ(mcu.requested_resets().size(), 1u);
    EXPECT_GE(mcu.requested_resets()[0].cycle, kPeriod);
    EXPECT_LE(mcu.requested_resets()[0].cycle, kPeriod + 1000);
    // WDTCR resets to 0: no second reset.
    EXPECT_EQ(mcu.resets(), 1u);
    EXPECT_EQ(mcu.read_ram_u8("boot_count"), 2);
    EXPECT_EQ(mcu.read_ram_u8("reset_flags"), 0x08);  // MCUCSR.WDRF
}

}  // namespace
}  // namespace avrbench
