// A scenario's timing expectation reports every bound it breaks, not only
// the first (tests/scenarios/blink_timer1_timing.yaml holds the hand count:
// the ISR takes 28 cycles, its latency is at most 5, it runs 99 times in
// 100 ms).
#include <gtest/gtest.h>

#include <fstream>

#include "support/Paths.hpp"
#include "support/RunCommand.hpp"
#include "verify/Scenario.hpp"

namespace avrbench {
namespace {

TEST(ProfileBounds, AnIsrExpectationReportsEveryBrokenBound) {
    const auto dir = test::scratch_dir("verdict-isr-bounds");
    const auto path = dir / "isr.yaml";
    std::ofstream(path) << "name: isr\n"
                        << "board: " << test::source_path("bench/boards/arduino-uno.yaml") << "\n"
                        << "firmware: {uno: blink_timer1}\n"
                        << "steps:\n  - delay: 100ms\n"
                        << "expect:\n  - isr: {vector: 11, max_cycles: 27, max_latency_cycles: 3, min_runs: 100}\n";
    const ScenarioResult r = run_scenario(load_scenario(path.string(), ::avrbench::test::firmware_dir()), {});
    EXPECT_FALSE(r.passed);
    ASSERT_EQ(r.expectation_failures.size(), 1u) << r.text();
    const std::string& text = r.expectation_failures[0];
    EXPECT_NE(text.find("vector 11 (TIMER1_COMPA) ran 99 times, expected at least 100"), std::string::npos) << text;
    EXPECT_NE(text.find("; and took up to 28 cycles (median 28), expected at most 27"), std::string::npos) << text;
    EXPECT_NE(text.find("; and started up to "), std::string::npos) << text;
    EXPECT_NE(text.find(" cycles after its flag, expected at most 3"), std::string::npos) << text;
}

}  // namespace
}  // namespace avrbench
