// The golden-timeline text format: exact round trip, compact run-length
// encoding, readable diffs, strict parsing.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/Errors.hpp"
#include "trace/TimelineText.hpp"

namespace avrbench {
namespace {

// A step train: n pulses, high `high` cycles, period `period`, starting at `start`.
void add_steps(Timeline& t, SignalId id, Cycle start, int n, Cycle high, Cycle period) {
    t.record(id, 0, 0);
    for (int i = 0; i < n; ++i) {
        t.record(id, start + static_cast<Cycle>(i) * period, 1);
        t.record(id, start + static_cast<Cycle>(i) * period + high, 0);
    }
}

TimelineHeader header() {
    TimelineHeader h;
    h.bench_version = "0.1.0";
    h.inputs = {{"firmware.uno", "ab12", "build/firmware/x.elf"}, {"board", "cd34", "bench/boards/b.yaml"}};
    h.end_cycle = 1'000'000;
    h.end_clock_hz = 16'000'000;
    return h;
}

TEST(TimelineText, RoundTripIsExact) {
    Timeline t;
    const SignalId step = t.add_signal({"uno", "PD2", SignalKind::Wire, 1, 16000000});
    const SignalId tx = t.add_signal({"uno", "uart0_tx", SignalKind::Bus, 8, 16000000});
    const SignalId pos = t.add_signal({"x", "position_mm", SignalKind::Real, 1, 20000000});
    add_steps(t, step, 1696, 1600, 32, 352);
    t.record(tx, 100, 'o');
    t.record(tx, 1460, 'k');
    t.record_real(pos, 0, 100.0);
    t.record_real(pos, 5, 100.0 + 1.0 / 3.0);  // not representable in short decimal: must survive exactly
    const std::string text = format_timeline_text(t, header());
    const ParsedTimeline parsed = parse_timeline_text(text, "golden.txt");
    EXPECT_EQ(format_timeline_text(parsed.timeline, parsed.header), text);
    ASSERT_EQ(parsed.header.inputs.size(), 2u);
    EXPECT_EQ(parsed.header.inputs[1].path, "bench/boards/b.yaml");
    const auto reals = changes_of(parsed.timeline, 2);
    ASSERT_EQ(reals.size(), 2u);
    EXPECT_EQ(reals[1].value.real, 100.0 + 1.0 / 3.0);
    EXPECT_EQ(parsed.timeline.signals()[2].clock_hz, 20000000u);
    // 1600 pulses = 3200 changes after the initial 0.
    EXPECT_EQ(changes_of(parsed.timeline, 0).size(), 3201u);
}

TEST(TimelineText, PeriodicStepsTakeAFewLines) {
    Timeline t;
    const SignalId step = t.add_signal({"uno", "PD2", SignalKind::Wire, 1, 16000000});
    add_steps(t, step, 1696, 1600, 32, 352);
    const std::string text = format_timeline_text(t, header());
    // Initial level, first rising edge, one repeat line for the 1599
    // (fall after 32, next rise after 320) pairs, and the last fall.
    EXPECT_NE(text.find("@uno.PD2\n0 0\n+1696 1\n*1599 +32 0 +320 1\n+32 0\n"), std::string::npos) << text;
}

TEST(TimelineText, OneShiftedStepIsAOneLineChange) {
    Timeline a, b;
    const SignalId sa = a.add_signal({"uno", "PD2", SignalKind::Wire, 1, 16000000});
    const SignalId sb = b.add_signal({"uno", "PD2", SignalKind::Wire, 1, 16000000});
    add_steps(a, sa, 1000, 100, 32, 400);
    add_steps(b, sb, 1000, 100, 32, 400);
    b.record(sb, 1000 + 50 * 400, 0);  // drop step 50's rising edge...
    b.record(sb, 1000 + 50 * 400 + 3, 1);  // ...and put it 3 cycles later
    const std::string ta = format_timeline_text(a, header());
    const std::string tb = format_timeline_text(b, header());
    EXPECT_NE(ta, tb);
    // The runs before and after the shifted step stay, so the text differs in a handful of lines.
    auto lines = [](const std::string& s) { return std::count(s.begin(), s.end(), '\n'); };
    EXPECT_LE(std::abs(lines(tb) - lines(ta)), 4);
    EXPECT_LE(lines(tb), 16);  // 8 header lines, and 8 for 100 pulses with one moved
}

TEST(TimelineText, ParseErrorsNameTheLine) {
    EXPECT_THROW(parse_timeline_text("hello\n", "g.txt"), BadInput);
    try {
        parse_timeline_text("avrbench-timeline 1\nsignal uno.PD2 wire 1 16000000\n@uno.PD3\n0 1\n", "g.txt");
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "g.txt:3: events for undeclared signal 'uno.PD3'");
    }
    try {
        parse_timeline_text("avrbench-timeline 1\nsignal uno.PD2 wire 1 16000000\n@uno.PD2\n0 1\n+x 0\n", "g.txt");
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "g.txt:5: 'x' is not a whole number");
    }
    // Two changes on one line are an error, not the first change alone (issue 36).
    try {
        parse_timeline_text("avrbench-timeline 1\nsignal uno.PD2 wire 1 16000000\n@uno.PD2\n0 1\n+17 0 +15 1\n", "g.txt");
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "g.txt:5: '+15' after a change (one item per line)");
    }
}

// Golden values no run can have: one line naming file and line, never an
// internal error or an allocation without end.
TEST(TimelineText, ImpossibleValuesAreFileLineErrors) {
    const std::string head = "avrbench-timeline 1\n";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"signal uno.tx bus 0 16000000\n", "g.txt:2: bus width 0 is not 1..64"},
        {"signal uno.tx bus 65 16000000\n", "g.txt:2: bus width 65 is not 1..64"},
        {"signal uno.PD2 wire 2 16000000\n", "g.txt:2: a wire is 1 bit wide, not 2"},
        {"signal uno.PD2 wire 1 0\n", "g.txt:2: clock 0 Hz is not 1 Hz .. 64 MHz"},
        {"signal uno.PD2 wire 1 16000000\nsignal uno.PD2 wire 1 16000000\n", "g.txt:3: signal 'uno.PD2' is declared twice"},
        {"signal .PD2 wire 1 16000000\n", "g.txt:2: signal '.PD2' has an empty scope or name"},
        {"end 0 0\n", "g.txt:2: end clock 0 Hz is not 1 Hz .. 64 MHz"},
        {"end 18446744073709551615 16000000\n", "g.txt:2: cycle count 18446744073709551615 is past any run's end"},
        // 10^12 repeats would allocate without end (about 6 GB before, for 1e9).
        {"signal uno.PD2 wire 1 16000000\n@uno.PD2\n*1000000000000 +10 1 +10 0\n",
         "g.txt:4: repeat count 1000000000000 is more than the events a golden may hold"},
        {"signal uno.PD2 wire 1 16000000\n@uno.PD2\n*40000000 +10 1 +10 0\n",
         "g.txt:4: more than 50000000 events (the most a golden timeline may hold)"},
        {"signal uno.PD2 wire 1 16000000\n@uno.PD2\n0 1\n+18446744073709551615 0\n",
         "g.txt:5: cycle count 18446744073709551615 is past any run's end"},
    };
    for (const auto& [body, message] : cases) {
        try {
            parse_timeline_text(head + body, "g.txt");
            ADD_FAILURE() << "accepted: " << body;
        } catch (const BadInput& e) {
            EXPECT_EQ(std::string(e.what()), message) << body;
        }
    }
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// Issue 36's case: a Timer1-compare stepper, 500 steps whose periods are
// 7965/7966/7967 cycles (interrupt latency) around the timer's exact 7966,
// 180-cycle pulses. Exact, it takes a line per edge; with a 4-cycle steps
// tolerance on the pin it is the nominal train in one `*n` line.
Timeline jittery_steps() {
    Timeline t;
    const SignalId id = t.add_signal({"uno", "PD2", SignalKind::Wire, 1, 16000000});
    t.record(id, 0, 0);
    const int jitter[] = {0, 1, -1, 1, 0, -1};  // latency around the timer's edge
    for (int i = 0; i < 500; ++i) {
        const Cycle rise = static_cast<Cycle>(20000 + i * 7966 + jitter[i % 6]);
        t.record(id, rise, 1);
        t.record(id, rise + 180 + static_cast<Cycle>(jitter[(i + 2) % 6] + 1), 0);
    }
    return t;
}

TEST(TimelineText, AJitteryConstantRateTrainIsItsNominalPeriodInOneLine) {
    const Timeline t = jittery_steps();
    TimelineHeader h = header();
    h.end_cycle = 5'000'000;  // past the 500th step (20000 + 500 x 7966 = 4 003 000)
    h.end_clock_hz = 16000000;
    const std::string exact = format_timeline_text(t, h);
    const std::string nominal = format_timeline_text(t, h, {{"uno.PD2", 4}});
    EXPECT_GT(std::count(exact.begin(), exact.end(), '\n'), 400);
    // Header lines, the signal, its first event and the block (and at most
    // one edge on each side of it).
    const auto at = nominal.find("@uno.PD2\n");
    ASSERT_NE(at, std::string::npos);
    const std::string events = nominal.substr(at);
    EXPECT_LE(std::count(events.begin(), events.end(), '\n'), 6) << events;
    // The period, not its jitter: 7966 = a 181-cycle pulse (180 + the mean
    // of the fall's extra cycle) and 7785 cycles low, 499 times after the
    // first rise.
    EXPECT_NE(events.find("*499 +181 0 +7785 1\n"), std::string::npos) << events;
    // Read back: the same number of edges, each rise within 4 cycles of the recorded one.
    const ParsedTimeline back = parse_timeline_text(nominal, "g.txt");
    const auto recorded = changes_of(t, 0);
    const auto golden = changes_of(back.timeline, 0);
    ASSERT_EQ(golden.size(), recorded.size());
    for (std::size_t i = 0; i < golden.size(); ++i) {
        const Cycle a = golden[i].cycle, b = recorded[i].cycle;
        EXPECT_LE(a > b ? a - b : b - a, 4u) << "edge " << i;
        EXPECT_EQ(golden[i].value.bits, recorded[i].value.bits);
    }
}

}  // namespace
}  // namespace avrbench
