// SignalChanges: a signal's changes in 8 bytes (wire) or 16 (bus, real) per
// change, the same changes as changes_of() gives from a Timeline.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "trace/SignalChanges.hpp"
#include "trace/TimelineText.hpp"

namespace avrbench {
namespace {

std::vector<TimelineEvent> all_of(const SignalChanges& c) {
    std::vector<TimelineEvent> out;
    for (std::size_t i = 0; i < c.size(); ++i) out.push_back(c[i]);
    return out;
}

// By hand: events as recorded, the changes they make.
TEST(SignalChanges, FinishKeepsTheLastValueAtACycleAndDropsRepeats) {
    SignalChanges wire(SignalKind::Wire);
    // (0,0) (5,0: repeat) (9,1) (9,0: same cycle, back to 0: no change at 9)
    // (12,1) (12,1) (20,0) (20,1) (20,0): at 20 the last value, 0.
    for (const auto& [c, v] : std::vector<std::pair<Cycle, int>>{{0, 0}, {5, 0}, {9, 1}, {9, 0}, {12, 1}, {12, 1}, {20, 0}, {20, 1}, {20, 0}}) {
        wire.add(c, static_cast<std::uint64_t>(v));
    }
    wire.finish();
    const auto got = all_of(wire);
    ASSERT_EQ(got.size(), 3u);
    EXPECT_EQ(got[0].cycle, 0u);
    EXPECT_EQ(got[0].value.bits, 0u);
    EXPECT_EQ(got[1].cycle, 12u);
    EXPECT_EQ(got[1].value.bits, 1u);
    EXPECT_EQ(got[2].cycle, 20u);
    EXPECT_EQ(got[2].value.bits, 0u);
    // Out of order: sorted by cycle first (stable), as changes_of sorts.
    SignalChanges bus(SignalKind::Bus);
    bus.add(30, 0x41);
    bus.add(10, 0x42);
    bus.add(10, 0x43);
    bus.add(20, 0x43);
    bus.finish();
    ASSERT_EQ(bus.size(), 2u);
    EXPECT_EQ(bus.cycle(0), 10u);
    EXPECT_EQ(bus.bits(0), 0x43u);
    EXPECT_EQ(bus.cycle(1), 30u);
    EXPECT_EQ(bus.bits(1), 0x41u);
}

// Against changes_of on seeded random recordings of every kind, longer than
// several of the store's chunks, in order and shuffled.
TEST(SignalChanges, TheSameChangesAsChangesOfForEveryKind) {
    std::mt19937_64 rng(37);
    const SignalInfo kinds[] = {
        {"m", "PB0", SignalKind::Wire, 1, 16000000},
        {"m", "uart0_tx", SignalKind::Bus, 8, 16000000},
        {"p", "degC", SignalKind::Real, 64, 16000000},
    };
    for (const SignalInfo& info : kinds) {
        for (const bool shuffled : {false, true}) {
            Timeline t;
            const SignalId id = t.add_signal(info);
            SignalChanges changes(info.kind);
            Cycle c = 0;
            for (int i = 0; i < 12000; ++i) {
                c += rng() % 3;  // repeats of a cycle are common
                Cycle at = c;
                if (shuffled && rng() % 10 == 0) at = c - std::min<Cycle>(c, rng() % 5);
                const double reals[] = {0.0, -0.0, 1.5, 2.25};
                if (info.kind == SignalKind::Real) {
                    const double v = reals[rng() % 4];
                    t.record_real(id, at, v);
                    TimelineEvent e{at, id, {}};
                    e.value.real = v;
                    changes.add(e);
                } else {
                    const std::uint64_t v = rng() % (info.kind == SignalKind::Wire ? 2 : 3);
                    t.record(id, at, v);
                    changes.add(at, v);
                }
            }
            changes.finish();
            const auto expected = changes_of(t, id);
            const auto got = all_of(changes);
            ASSERT_EQ(got.size(), expected.size()) << info.name << (shuffled ? " shuffled" : "");
            EXPECT_GT(expected.size(), 1024u * 2) << "spans several chunks";
            for (std::size_t i = 0; i < got.size(); ++i) {
                ASSERT_EQ(got[i].cycle, expected[i].cycle) << info.name << " change " << i;
                ASSERT_EQ(got[i].value.bits, expected[i].value.bits) << info.name << " change " << i;
            }
        }
    }
}

}  // namespace
}  // namespace avrbench
