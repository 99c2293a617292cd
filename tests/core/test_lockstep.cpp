// Several MCUs on one board advance in simulated-time order with skew
// bounded by one instruction.
#include <gtest/gtest.h>

#include "mcu/ElfImage.hpp"
#include "mcu/Lockstep.hpp"
#include "support/Paths.hpp"
#include "trace/Recorder.hpp"

namespace avrbench {
namespace {

// The longest AVR instruction takes 5 cycles (CALL on 22-bit PC parts, AVR
// Instruction Set Manual); an interrupt entry adds 4-5. Skew between two
// cores is one such step of the core that ran last.
constexpr double kMaxSkewSeconds = 10.0 / 16e6;

double seconds_of(const Mcu& m) { return static_cast<double>(m.cycle()) / m.frequency_hz(); }

struct Wired {
    Mcu blinker{ElfImage::load(test::firmware("blink_timer1")), McuOptions{"blinker", "", 0}};
    Mcu mirror;
    explicit Wired(std::uint32_t mirror_hz)
        : mirror(ElfImage::load(test::firmware("pin_mirror")), McuOptions{"mirror", "", mirror_hz}) {
        // The net blinker.PB5 -> mirror.PB0.
        blinker.pin("PB5").on_change([this](Cycle, bool level) {
            max_skew_seen = std::max(max_skew_seen, std::abs(seconds_of(blinker) - seconds_of(mirror)));
            mirror.pin("PB0").drive(level);
        });
    }
    double max_skew_seen = 0;
};

void expect_mirror_follows(std::uint32_t mirror_hz) {
    Wired board(mirror_hz);
    Timeline timeline;
    Recorder recorder(timeline);
    const SignalId in = recorder.trace_pin(board.blinker, board.blinker.pin("PB5"));
    const SignalId out = recorder.trace_pin(board.mirror, board.mirror.pin("PB1"));
    Lockstep lockstep;
    lockstep.add(board.blinker);
    lockstep.add(board.mirror);
    ASSERT_EQ(lockstep.run_until_ps(20'000'000'000ULL), StopReason::ReachedTarget);  // 20 ms
    EXPECT_LE(board.max_skew_seen, kMaxSkewSeconds);

    std::vector<double> in_s, out_s;
    for (const auto& e : timeline.events()) {
        const double t = static_cast<double>(e.cycle) / timeline.signals()[e.signal].clock_hz;
        if (e.signal == in) in_s.push_back(t);
        if (e.signal == out) out_s.push_back(t);
    }
    in_s.erase(in_s.begin());
    out_s.erase(out_s.begin());
    ASSERT_GE(in_s.size(), 19u);  // 1 ms toggles over 20 ms
    ASSERT_EQ(out_s.size(), in_s.size());
    // The mirror's loop (IN, SBRC/SBRS, CBI/SBI, RJMP) sees the input within a
    // handful of its cycles; 20 cycles bounds it generously at either clock.
    for (std::size_t i = 0; i < in_s.size(); ++i) {
        EXPECT_GT(out_s[i], in_s[i]);
        EXPECT_LT(out_s[i] - in_s[i], 20.0 / mirror_hz) << "edge " << i;
    }
}

TEST(Lockstep, MirrorFollowsBlinkerAtTheSameClock) { expect_mirror_follows(16000000); }

TEST(Lockstep, MirrorFollowsBlinkerAtADifferentClock) { expect_mirror_follows(20000000); }

TEST(Lockstep, FiveCoresReachTheSameTime) {
    std::vector<std::unique_ptr<Mcu>> cores;
    Lockstep lockstep;
    for (int i = 0; i < 5; ++i) {
        cores.push_back(std::make_unique<Mcu>(ElfImage::load(test::firmware(i % 2 ? "sleep_idle" : "busy_poll")),
                                              McuOptions{"mcu" + std::to_string(i), "", 0}));
        lockstep.add(*cores.back());
    }
    ASSERT_EQ(lockstep.run_until_ps(5'000'000'000ULL), StopReason::ReachedTarget);  // 5 ms = 80000 cycles
    for (const auto& m : cores) {
        EXPECT_GE(m->cycle(), 80000u);
        EXPECT_LE(m->cycle(), 80000u + 5);
    }
}

}  // namespace
}  // namespace avrbench
