// The timer model's replay of a steady period (periph/timer/TimerModel.cpp:
// events taken from a record of one period instead of computed) against the
// model computing every event: every firmware the build makes runs 20 ms
// both ways, with every pin and USART0 traced and a few lines of serial
// input, and must end in the same state (cycle, PC, registers, I/O, RAM,
// steps) with the same timeline and findings. Idle-loop skipping stays on,
// as the CLI runs it.
#include <gtest/gtest.h>

#include <string>

#include "periph/Fixes.hpp"
#include "support/EveryFirmware.hpp"

namespace avrbench {
namespace {

// Restores replay (the default) however the test ends.
struct ReplaySetting {
    explicit ReplaySetting(bool on) { set_timer_replay(on); }
    ~ReplaySetting() { set_timer_replay(true); }
};

test::TracedEnd run(const std::string& name, bool replay) {
    const ReplaySetting setting(replay);
    return test::run_traced(name, McuOptions{});
}

TEST(TimerReplay, EndsWhereTheModelComputingEveryEventEndsOnEveryFirmware) {
    const auto names = test::all_firmware();
    ASSERT_GT(names.size(), 100u);
    for (const auto& name : names) {
        const test::TracedEnd a = run(name, false), b = run(name, true);
        test::expect_same_end(a, b, name);
        EXPECT_EQ(a.steps, b.steps) << name;
    }
}

}  // namespace
}  // namespace avrbench
