// The streamed dump is byte for byte the dump written from the whole
// timeline, whatever the drain points, and holds back only what is not yet
// settled.
#include <gtest/gtest.h>

#include <random>

#include "trace/Timeline.hpp"
#include "trace/TraceTestSupport.hpp"
#include "trace/VcdWriter.hpp"

namespace avrbench {
namespace {

using trace_test::ScratchDir;
using trace_test::read_text;

constexpr std::uint32_t k16MHz = 16000000;
constexpr std::uint32_t k14MHz = 14745600;  // no exact VCD unit: times rounded to 1 fs

// Two clock domains, a bus and a real, values at time 0, repeats, several
// events at one cycle, and the second domain recorded slightly behind the
// first (as lockstepped MCUs do), in `steps` slices.
struct Recording {
    Timeline timeline;
    SignalId a, b, bus, real;
    Recording() {
        a = timeline.add_signal({"m1", "PB5", SignalKind::Wire, 1, k16MHz});
        bus = timeline.add_signal({"m1", "uart0_tx", SignalKind::Bus, 8, k16MHz, true});
        b = timeline.add_signal({"m2", "PD2", SignalKind::Wire, 1, k14MHz});
        real = timeline.add_signal({"plant", "block_degC", SignalKind::Real, 1, k16MHz});
        timeline.add_alias(a, "nets", "led");
    }
    // Records slice `i` (1 ms of m1's time) and returns the picoseconds both domains have reached.
    Picoseconds record_slice(int i, std::mt19937& rng) {
        const Cycle m1_start = static_cast<Cycle>(i) * 16000, m2_start = static_cast<Cycle>(i) * 14746;
        for (int k = 0; k < 20; ++k) {
            const Cycle c1 = m1_start + rng() % 16000;
            timeline.record(a, c1, rng() % 2);
            if (k % 5 == 0) timeline.record(bus, c1, rng() % 256);
            timeline.record(a, c1, rng() % 2);  // a second value at the same cycle: the last wins
            timeline.record_real(real, m1_start + static_cast<Cycle>(k) * 800, 25.0 + k * 0.125);
            timeline.record(b, m2_start + rng() % 14000, rng() % 2);
        }
        return static_cast<Picoseconds>(i + 1) * 1'000'000'000ULL - 60'000'000ULL;  // m2 is ~60 us behind
    }
};

TEST(VcdStream, SameBytesAsTheWholeTimelineWhateverTheDrainPoints) {
    ScratchDir dir;
    std::mt19937 rng_whole(7), rng_stream(7);
    Recording whole, streamed;
    whole.timeline.record(whole.a, 0, 1);
    streamed.timeline.record(streamed.a, 0, 1);
    VcdStream stream(streamed.timeline, dir.file("streamed.vcd"));
    for (int i = 0; i < 50; ++i) {
        whole.record_slice(i, rng_whole);
        const Picoseconds settled = streamed.record_slice(i, rng_stream);
        // Events are recorded in time order per domain, not across them:
        // drain only up to where both have reached, with some slices skipped.
        if (i % 3 != 1) stream.drain(streamed.timeline, settled > 200'000'000ULL ? settled - 200'000'000ULL : 0);
    }
    VcdOptions end;
    end.end_cycle = 50 * 16000 + 5;
    const VcdResult streamed_result = stream.finish(streamed.timeline, end);
    const VcdResult whole_result = write_vcd(whole.timeline, dir.file("whole.vcd"), end);
    EXPECT_EQ(read_text(dir.file("streamed.vcd")), read_text(dir.file("whole.vcd")));
    EXPECT_EQ(streamed_result.value_changes, whole_result.value_changes);
    EXPECT_EQ(streamed_result.end_time, whole_result.end_time);
    EXPECT_GT(whole_result.value_changes, 1000u);  // the comparison compared something
    // Nothing is left in memory after the stream took it.
    EXPECT_TRUE(streamed.timeline.events().empty());
    EXPECT_EQ(streamed.timeline.recorded_count(), whole.timeline.recorded_count());
}

TEST(VcdStream, HoldsBackOnlyWhatIsNotSettled) {
    ScratchDir dir;
    Timeline t;
    const SignalId a = t.add_signal({"m", "PB0", SignalKind::Wire, 1, k16MHz});
    VcdStream stream(t, dir.file("held.vcd"));
    for (Cycle c = 0; c < 1600; c += 16) t.record(a, c, (c / 16) % 2);  // 100 events, 1 us apart
    // Settled up to 50 us (cycle 800): events at cycles 0..800 go, 816..1584 wait (49 of them).
    stream.drain(t, 50'000'000ULL);
    EXPECT_EQ(stream.held_events(), 49u);
    EXPECT_TRUE(t.events().empty());
    stream.finish(t, VcdOptions{});
    EXPECT_EQ(stream.held_events(), 0u);
}

TEST(VcdStream, AnEventForATimeAlreadyWrittenIsAnError) {
    ScratchDir dir;
    Timeline t;
    const SignalId a = t.add_signal({"m", "PB0", SignalKind::Wire, 1, k16MHz});
    VcdStream stream(t, dir.file("late.vcd"));
    t.record(a, 1600, 1);
    stream.drain(t, 200'000'000ULL);  // 200 us: cycle 1600 (100 us) is written
    t.record(a, 160, 0);              // 10 us: too late
    EXPECT_THROW(stream.drain(t, 300'000'000ULL), std::logic_error);
}

}  // namespace
}  // namespace avrbench
