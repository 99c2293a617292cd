#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "trace/Timeline.hpp"

namespace avrbench {
namespace {

TEST(Timeline, AddSignalReturnsDenseIdsAndFindLooksThemUp) {
    Timeline timeline;
    EXPECT_EQ(timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, 16000000}), 0u);
    EXPECT_EQ(timeline.add_signal({"mcu", "portb", SignalKind::Bus, 8, 16000000}), 1u);
    EXPECT_EQ(timeline.add_signal({"heater", "PB5", SignalKind::Real, 1, 16000000}), 2u);
    EXPECT_EQ(timeline.find("mcu", "portb"), 1);
    EXPECT_EQ(timeline.find("heater", "PB5"), 2);  // same name, other scope
    EXPECT_EQ(timeline.find("mcu", "PB6"), -1);
    EXPECT_EQ(timeline.find("nope", "PB5"), -1);
    EXPECT_EQ(timeline.signals().size(), 3u);
}

TEST(Timeline, RejectsSignalsAViewerCouldNotShow) {
    Timeline timeline;
    timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, 16000000});
    EXPECT_THROW(timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, 16000000}), std::invalid_argument);
    EXPECT_THROW(timeline.add_signal({"", "a", SignalKind::Wire, 1, 16000000}), std::invalid_argument);
    EXPECT_THROW(timeline.add_signal({"mcu", "", SignalKind::Wire, 1, 16000000}), std::invalid_argument);
    EXPECT_THROW(timeline.add_signal({"mcu", "a b", SignalKind::Wire, 1, 16000000}), std::invalid_argument);
    EXPECT_THROW(timeline.add_signal({"m\tcu", "a", SignalKind::Wire, 1, 16000000}), std::invalid_argument);
    EXPECT_THROW(timeline.add_signal({"mcu", "w", SignalKind::Wire, 8, 16000000}), std::invalid_argument);
    EXPECT_THROW(timeline.add_signal({"mcu", "b0", SignalKind::Bus, 0, 16000000}), std::invalid_argument);
    EXPECT_THROW(timeline.add_signal({"mcu", "b65", SignalKind::Bus, 65, 16000000}), std::invalid_argument);
    EXPECT_THROW(timeline.add_signal({"mcu", "clk0", SignalKind::Wire, 1, 0}), std::invalid_argument);
    EXPECT_EQ(timeline.signals().size(), 1u);  // nothing half-registered
    try {
        timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, 16000000});
        FAIL() << "duplicate accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("mcu.PB5"), std::string::npos) << e.what();
    }
}

TEST(Timeline, RecordKeepsRecordOrderAndValues) {
    Timeline timeline;
    const SignalId pin = timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, 16000000});
    const SignalId temp = timeline.add_signal({"heater", "temp_degC", SignalKind::Real, 64, 16000000});
    timeline.record(pin, 10, 1);
    timeline.record_real(temp, 5, 21.5);
    ASSERT_EQ(timeline.events().size(), 2u);
    EXPECT_EQ(timeline.events()[0].cycle, 10u);
    EXPECT_EQ(timeline.events()[0].value.bits, 1u);
    EXPECT_EQ(timeline.events()[1].cycle, 5u);
    EXPECT_EQ(timeline.events()[1].value.real, 21.5);
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(TimelineLimit, EventsBeyondTheHeldLimitAreDroppedAndCounted) {
    Timeline t;
    const SignalId a = t.add_signal({"m", "PB0", SignalKind::Wire, 1, 16000000});
    t.set_max_held_events(3);
    for (Cycle c = 0; c < 5; ++c) t.record(a, c, c % 2);
    t.record_real(a, 6, 1.0);
    EXPECT_EQ(t.events().size(), 3u);
    EXPECT_TRUE(t.overflowed());
    EXPECT_EQ(t.dropped(), 3u);
    EXPECT_NE(t.overflow_message().find("more than 3 signal changes"), std::string::npos) << t.overflow_message();
    EXPECT_NE(t.overflow_message().find("3 were dropped"), std::string::npos) << t.overflow_message();
    // Taking the events (a streamed VCD) makes room again.
    EXPECT_EQ(t.take_events().size(), 3u);
    t.record(a, 7, 1);
    EXPECT_EQ(t.events().size(), 1u);
    EXPECT_EQ(t.recorded_count(), 4u);
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// keep_when_taken: a take hands over every new event; the kept signals' stay
// readable in events(), ahead of what is recorded after, and are not handed
// over again.
TEST(TimelineKeep, ATakeHandsOverEverythingAndLeavesTheKeptSignals) {
    Timeline t;
    const SignalId step = t.add_signal({"m", "PB0", SignalKind::Wire, 1, 16000000});
    const SignalId pos = t.add_signal({"x", "position_mm", SignalKind::Real, 1, 16000000});
    t.keep_when_taken({false, true});
    t.record(step, 1, 1);
    t.record_real(pos, 2, 0.5);
    t.record(step, 3, 0);
    std::vector<TimelineEvent> out;
    t.take_events_into(out);
    ASSERT_EQ(out.size(), 3u);
    EXPECT_EQ(out[1].signal, pos);
    ASSERT_EQ(t.events().size(), 1u);
    EXPECT_EQ(t.events()[0].cycle, 2u);
    t.record(step, 4, 1);
    t.record_real(pos, 5, 0.6);
    t.take_events_into(out);
    ASSERT_EQ(out.size(), 2u);  // the kept event of cycle 2 is not handed over twice
    EXPECT_EQ(out[0].cycle, 4u);
    ASSERT_EQ(t.events().size(), 2u);
    EXPECT_EQ(t.events()[1].cycle, 5u);
    EXPECT_EQ(t.recorded_count(), 5u);
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// stream_to: every event reaches the sink once, in record order, in batches
// of the size asked for; the timeline never holds more than a batch, and the
// held-events cap counts what the sink was handed.
TEST(TimelineStream, TheSinkGetsEveryEventInOrderAndTheTimelineHoldsAtMostABatch) {
    Timeline t;
    const SignalId a = t.add_signal({"m", "PB0", SignalKind::Wire, 1, 16000000});
    const SignalId r = t.add_signal({"p", "degC", SignalKind::Real, 1, 16000000});
    std::vector<TimelineEvent> got;
    std::size_t largest_batch = 0, most_held = 0;
    t.stream_to(
        [&](const std::vector<TimelineEvent>& batch) {
            largest_batch = std::max(largest_batch, batch.size());
            got.insert(got.end(), batch.begin(), batch.end());
        },
        7);
    for (Cycle c = 0; c < 1000; ++c) {
        if (c % 3 == 0) {
            t.record_real(r, c, 0.5 * static_cast<double>(c));
        } else {
            t.record(a, c, c % 2);
        }
        most_held = std::max(most_held, t.events().size());
    }
    EXPECT_LE(most_held, 7u);
    EXPECT_EQ(largest_batch, 7u);
    t.flush_stream();
    EXPECT_TRUE(t.events().empty());
    EXPECT_FALSE(t.overflowed());
    EXPECT_EQ(t.recorded_count(), 1000u);
    ASSERT_EQ(got.size(), 1000u);
    for (Cycle c = 0; c < 1000; ++c) {
        EXPECT_EQ(got[c].cycle, c);
        if (c % 3 == 0) {
            EXPECT_EQ(got[c].signal, r);
            EXPECT_EQ(got[c].value.real, 0.5 * static_cast<double>(c));
        } else {
            EXPECT_EQ(got[c].signal, a);
            EXPECT_EQ(got[c].value.bits, c % 2);
        }
    }
    // A cap of 1003 events handed over: 3 more, then every event is dropped.
    t.set_max_held_events(1003);
    for (Cycle c = 1000; c < 1020; ++c) t.record(a, c, c % 2);
    t.flush_stream();
    EXPECT_EQ(got.size(), 1003u);
    EXPECT_EQ(got.back().cycle, 1002u);
    EXPECT_EQ(t.dropped(), 17u);
    EXPECT_TRUE(t.overflowed());
    // Without the sink the cap applies to what the timeline holds.
    Timeline u;
    const SignalId b = u.add_signal({"m", "PB0", SignalKind::Wire, 1, 16000000});
    u.stream_to([](const std::vector<TimelineEvent>&) {}, 4);
    u.stream_to(nullptr);
    u.set_max_held_events(5);
    for (Cycle c = 0; c < 10; ++c) u.record(b, c, c % 2);
    EXPECT_EQ(u.events().size(), 5u);
    EXPECT_EQ(u.dropped(), 5u);
}

}  // namespace
}  // namespace avrbench
