// stepdir_test (firmware/boards/stepdir_test) driven through the UART host:
// the STEP/DIR/ENABLE pins, watched directly on the MCU, must show exactly the
// pulses its README documents.
//
// Hand calculation (README "Pulse timing"): at 16 MHz, 1 us = 16 cycles, and
//   STEP high  = 16 * W cycles          (W = 5 by default:  80)
//   STEP low   = 16 * L cycles          (L = 45 by default: 720)
//   period     = 16 * (W + L) cycles    (800 = 50 us = 20 kHz by default)
//   DIR setup  = 16 * S cycles          (S = 5 by default:  80), S = 0: DIR
//                changes in the same OUT as the first STEP rising edge
// when no byte arrives during the move (send-and-wait: the host is waiting
// for the ok, so nothing does).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "stimulus/UartHost.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace stepdir_fw_test {

constexpr Cycle kCyclesPerUs = 16;  // 16 MHz

struct Edge {
    Cycle cycle;
    bool level;
};

struct StepDirRun {
    Mcu mcu{ElfImage::load(test::firmware("stepdir_test"))};
    UartHost host{mcu, 0, [] {
                      UartHostOptions o;
                      o.startup = Startup::WaitForBanner;
                      return o;
                  }()};
    std::vector<Edge> step;       // PD2, X STEP
    std::vector<Edge> dir;        // PD5, X DIR
    std::vector<Edge> enable;     // PB0, active low
    std::vector<bool> dir_at_rise;  // PD5's level at each PD2 rising edge

    StepDirRun() {
        mcu.pin("PD2").on_change([this](Cycle c, bool level) {
            step.push_back({c, level});
            if (level) dir_at_rise.push_back(mcu.pin("PD5").level());
        });
        mcu.pin("PD5").on_change([this](Cycle c, bool level) { dir.push_back({c, level}); });
        mcu.pin("PB0").on_change([this](Cycle c, bool level) { enable.push_back({c, level}); });
    }

    void run(const std::string& lines) {
        host.add_lines(lines);
        ASSERT_TRUE(host.run_until_finished(2.0)) << host.tail(10);
        ASSERT_TRUE(host.done()) << host.failure_message() << "\n" << host.tail(10);
    }

    std::vector<Cycle> rising() const {
        std::vector<Cycle> out;
        for (const auto& e : step) {
            if (e.level) out.push_back(e.cycle);
        }
        return out;
    }
};

TEST(StepDirFw, BannerThenOkForEachCommand) {
    StepDirRun r;
    r.run("E1\nW5\nL45\nS5\n");
    EXPECT_EQ(*r.host.banner(), "stepdir_test ready");
    EXPECT_EQ(r.host.oks(), 4u);
}

TEST(StepDirFw, X1600GivesExactly1600PulsesOfTheDocumentedWidth) {
    StepDirRun r;
    r.run("E1\nX1600\n");
    const auto rises = r.rising();
    ASSERT_EQ(rises.size(), 1600u);
    // Each rising edge has a falling edge: 3200 STEP edges in all.
    ASSERT_EQ(r.step.size(), 3200u);
    // DIR (PD5) high for a positive move (README), at every rising edge.
    ASSERT_EQ(r.dir_at_rise.size(), 1600u);
    for (std::size_t i = 0; i < r.dir_at_rise.size(); ++i) ASSERT_TRUE(r.dir_at_rise[i]) << "step " << i;

    for (std::size_t i = 0; i + 1 < r.step.size(); i += 2) {
        ASSERT_TRUE(r.step[i].level);
        ASSERT_FALSE(r.step[i + 1].level);
        // High: 16 * W = 16 * 5 = 80 cycles (5 us).
        ASSERT_EQ(r.step[i + 1].cycle - r.step[i].cycle, 5 * kCyclesPerUs) << "pulse " << i / 2;
        if (i + 2 < r.step.size()) {
            // Low: 16 * L = 16 * 45 = 720 cycles (45 us).
            ASSERT_EQ(r.step[i + 2].cycle - r.step[i + 1].cycle, 45 * kCyclesPerUs) << "pulse " << i / 2;
        }
    }
    // Period 800 cycles, so the move spans 1599 * 800 cycles between first and
    // last rising edges (= 79.95 ms of 20 kHz stepping).
    EXPECT_EQ(rises.back() - rises.front(), 1599u * 800u);

    // DIR went high once, 16 * S = 80 cycles (5 us) before the first step.
    ASSERT_EQ(r.dir.size(), 1u);
    EXPECT_TRUE(r.dir[0].level);
    EXPECT_EQ(rises.front() - r.dir[0].cycle, 5 * kCyclesPerUs);

    // The ok comes after the move: last falling edge + the final 720-cycle low.
    const auto received = r.host.transcript();
    EXPECT_GT(received.back().cycle, r.step.back().cycle + 45 * kCyclesPerUs);
}

TEST(StepDirFw, NegativeMoveSetsDirLowAndBothAreCounted) {
    StepDirRun r;
    r.run("E1\nX100\nX-40\n?\n");
    const auto rises = r.rising();
    ASSERT_EQ(rises.size(), 140u);  // 100 + 40
    for (std::size_t i = 0; i < 100; ++i) ASSERT_TRUE(r.dir_at_rise[i]) << i;
    for (std::size_t i = 100; i < 140; ++i) ASSERT_FALSE(r.dir_at_rise[i]) << i;
    ASSERT_EQ(r.dir.size(), 2u);  // up for X100, down for X-40
    EXPECT_FALSE(r.dir[1].level);
    EXPECT_EQ(rises[100] - r.dir[1].cycle, 5 * kCyclesPerUs);  // DIR setup 16 * S
    // The firmware's position report: +100 - 40 = 60.
    bool seen = false;
    for (const auto& e : r.host.transcript()) seen = seen || e.text == "X:60 Y:0 Z:0";
    EXPECT_TRUE(seen) << r.host.tail(6);
    EXPECT_EQ(r.mcu.read_ram_u8("rx_overflow"), 0);
}

TEST(StepDirFw, SettingsChangeTheTimingExactly) {
    StepDirRun r;
    r.run("E1\nW10\nL3\nS20\nX3\n");
    ASSERT_EQ(r.step.size(), 6u);
    // W10: 16 * 10 = 160 cycles high; L3: 16 * 3 = 48 cycles low.
    EXPECT_EQ(r.step[1].cycle - r.step[0].cycle, 160u);
    EXPECT_EQ(r.step[2].cycle - r.step[1].cycle, 48u);
    EXPECT_EQ(r.step[3].cycle - r.step[2].cycle, 160u);
    EXPECT_EQ(r.step[4].cycle - r.step[3].cycle, 48u);
    EXPECT_EQ(r.step[5].cycle - r.step[4].cycle, 160u);
    // S20: DIR 16 * 20 = 320 cycles before the first rising edge.
    ASSERT_EQ(r.dir.size(), 1u);
    EXPECT_EQ(r.step[0].cycle - r.dir[0].cycle, 320u);
}

TEST(StepDirFw, ZeroSetupPutsTheDirChangeOnTheStepEdge) {
    StepDirRun r;
    r.run("E1\nS0\nX2\nX-2\n");
    const auto rises = r.rising();
    ASSERT_EQ(rises.size(), 4u);
    ASSERT_EQ(r.dir.size(), 2u);
    // S0: one OUT writes DIR and STEP, so both edges carry the same cycle
    // (a DIR setup time of 0 ns: any driver's setup check must fire).
    EXPECT_EQ(r.dir[0].cycle, rises[0]);
    EXPECT_TRUE(r.dir[0].level);
    EXPECT_EQ(r.dir[1].cycle, rises[2]);
    EXPECT_FALSE(r.dir[1].level);
}

TEST(StepDirFw, EnableIsPb0ActiveLow) {
    StepDirRun r;
    // After reset the firmware disables the drivers: PB0 high (main() runs
    // after avr-libc's startup code, ~1600 cycles in).
    r.mcu.run_for(5000);
    EXPECT_TRUE(r.mcu.pin("PB0").level());
    r.run("E1\nE0\nE1\n");
    ASSERT_EQ(r.enable.size(), 4u);  // high at init, low, high, low
    EXPECT_TRUE(r.enable[0].level);
    EXPECT_FALSE(r.enable[1].level);
    EXPECT_TRUE(r.enable[2].level);
    EXPECT_FALSE(r.enable[3].level);
}

TEST(StepDirFw, BadCommandsGetGrblStyleErrors) {
    StepDirRun r;
    // README: error:1 unknown letter, error:2 bad number, error:3 out of range.
    r.run("G1\nXa\nW101\nX\n");
    std::vector<std::string> responses;
    for (const auto& e : r.host.events()) responses.push_back(e.response);
    EXPECT_EQ(responses, (std::vector<std::string>{"error:1", "error:2", "error:3", "error:2"}));
    EXPECT_TRUE(r.step.empty());
}

}  // namespace stepdir_fw_test
}  // namespace avrbench
