#include <gtest/gtest.h>

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

TEST(Scheduler, EventsFireInOrderAtTheFirstInstructionBoundary) {
    Mcu mcu(ElfImage::load(test::firmware("busy_poll")));
    std::vector<std::pair<Cycle, Cycle>> fired;  // scheduled, actual
    for (Cycle c : {5000u, 1000u, 3000u, 3000u}) {
        mcu.scheduler().at(c, [&](Cycle scheduled) { fired.emplace_back(scheduled, mcu.cycle()); });
    }
    mcu.run_for(10000);
    ASSERT_EQ(fired.size(), 4u);
    const Cycle expected[] = {1000, 3000, 3000, 5000};
    for (std::size_t i = 0; i < fired.size(); ++i) {
        EXPECT_EQ(fired[i].first, expected[i]);
        // An instruction takes at most 5 cycles, so the boundary is that close.
        EXPECT_GE(fired[i].second, expected[i]);
        EXPECT_LE(fired[i].second, expected[i] + 5);
    }
}

TEST(Scheduler, EventWhileAsleepStopsTheJumpThere) {
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    // The first wake-up is at ~160000 cycles; an event at 50000 must be seen
    // at 50000 (+1: simavr's sleep lands one cycle past the timer), not later.
    Cycle seen = 0;
    mcu.scheduler().at(50000, [&](Cycle) { seen = mcu.cycle(); });
    mcu.run_for(100000);
    EXPECT_GE(seen, 50000u);
    EXPECT_LE(seen, 50001u);
}

TEST(Scheduler, CallbacksMayScheduleMore) {
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    int count = 0;
    std::function<void(Cycle)> tick = [&](Cycle scheduled) {
        ++count;
        if (count < 10) mcu.scheduler().at(scheduled + 1000, tick);
    };
    mcu.scheduler().at(1000, tick);
    mcu.run_for(20000);
    EXPECT_EQ(count, 10);
}

TEST(Scheduler, RunUntilStopsAtTheTargetEvenWhileAsleep) {
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    EXPECT_EQ(mcu.run_until(70000), StopReason::ReachedTarget);
    EXPECT_GE(mcu.cycle(), 70000u);
    EXPECT_LE(mcu.cycle(), 70005u);
}

}  // namespace
}  // namespace avrbench
