// SLEEP and idle never wait on the wall clock: a sleeping core's cycle counter
// jumps straight to the next event.
#include <gtest/gtest.h>

extern "C" {
#include <sim_avr.h>
}

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"
#include "trace/Recorder.hpp"

namespace avrbench {
namespace {

// sleep_idle: Timer1 CTC, prescaler 8, OCR1A = 19999 -> a compare match every
// (19999 + 1) * 8 = 160000 cycles = 10 ms at 16 MHz (ATmega328P §16.9.2).
constexpr Cycle kWakeupPeriodCycles = (19999 + 1) * 8;

TEST(VirtualTime, SleepIsNeverAWallClockWait) {
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    // simavr's default raw sleep callback calls usleep(); the bench replaces it.
    EXPECT_TRUE(mcu.sleeps_in_virtual_time());
}

TEST(VirtualTime, EachSleepIsOneJumpToTheWakeupEvent) {
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    Timeline timeline;
    Recorder recorder(timeline);
    const SignalId led = recorder.trace_pin(mcu, mcu.pin("PB5"));

    // Reach the first SLEEP.
    while (!mcu.sleeping() && mcu.cycle() < kWakeupPeriodCycles) ASSERT_TRUE(mcu.step());
    ASSERT_TRUE(mcu.sleeping());

    // From now on every step either executes one instruction (at most 5
    // cycles, plus an interrupt entry of 4-5) or, when it executes SLEEP,
    // jumps the whole way to the wake-up: nothing in between, no creeping
    // through the sleep cycle by cycle.
    std::vector<Cycle> sleep_jump_ends;
    const Cycle end = mcu.cycle() + 10 * kWakeupPeriodCycles;
    while (mcu.cycle() < end) {
        const Cycle before = mcu.cycle();
        ASSERT_TRUE(mcu.step());
        const Cycle advance = mcu.cycle() - before;
        if (advance <= 10) continue;
        EXPECT_GT(advance, kWakeupPeriodCycles - 1000) << "a sleep that did not jump";
        sleep_jump_ends.push_back(mcu.cycle());
    }
    EXPECT_GE(sleep_jump_ends.size(), 9u);
    EXPECT_LE(sleep_jump_ends.size(), 11u);

    std::vector<Cycle> toggles;
    for (const auto& e : timeline.events()) {
        if (e.signal == led) toggles.push_back(e.cycle);
    }
    toggles.erase(toggles.begin());  // level at trace start
    ASSERT_GE(toggles.size(), 9u);
    // Wake-ups are exactly one compare period apart: a sleeping core has no
    // instruction in progress, so the ISR latency does not jitter.
    for (std::size_t i = 1; i < toggles.size(); ++i) {
        EXPECT_EQ(toggles[i] - toggles[i - 1], kWakeupPeriodCycles);
    }
    // Each jump ends at the wake-up that the following toggle answers: the
    // ISR entry and the PINB write take a few dozen cycles, never a period.
    for (Cycle jump_end : sleep_jump_ends) {
        auto next = std::lower_bound(toggles.begin(), toggles.end(), jump_end);
        if (next == toggles.end()) continue;
        EXPECT_LT(*next - jump_end, 100u);
    }
}

TEST(VirtualTime, OneSimulatedSecondOfSleepTakesFewSteps) {
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    const Cycle one_second = 16000000;
    ASSERT_EQ(mcu.run_until(one_second), StopReason::ReachedTarget);
    // 100 wake-ups (1 s / 10 ms); each costs one sleep jump plus the ISR's
    // instructions (prologue, toggle, counter, epilogue: well under 100).
    EXPECT_LT(mcu.steps(), 100u * 100u);
    const std::uint16_t wakeups = mcu.read_ram_u16("wakeups");
    EXPECT_GE(wakeups, 99);
    EXPECT_LE(wakeups, 100);
}

}  // namespace
}  // namespace avrbench
