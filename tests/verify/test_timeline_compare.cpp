// Comparators: each rule catches what it must and tolerates what it may; the
// report names the first divergence with context and summarises every channel.
#include <gtest/gtest.h>

#include "verify/TimelineCompare.hpp"

namespace avrbench {
namespace {

constexpr std::uint32_t kHz = 16000000;

Timeline steps(int n, Cycle period, Cycle shift_step = 0, Cycle shift_by = 0, int drop_step = -1) {
    Timeline t;
    const SignalId id = t.add_signal({"uno", "PD2", SignalKind::Wire, 1, kHz});
    t.record(id, 0, 0);
    for (int i = 0; i < n; ++i) {
        if (i == drop_step) continue;
        const Cycle at = 1000 + static_cast<Cycle>(i) * period + (static_cast<Cycle>(i) == shift_step ? shift_by : 0);
        t.record(id, at, 1);
        t.record(id, at + 32, 0);
    }
    return t;
}

CompareOptions rule(RuleKind kind, double cycles = 0, double rel = 0) {
    CompareOptions o;
    ChannelRule r;
    r.kind = kind;
    r.tolerance_cycles = cycles;
    r.tolerance_rel = rel;
    o.rules.push_back(r);
    return o;
}

TEST(TimelineCompare, IdenticalTimelinesPassEveryRule) {
    for (RuleKind k : {RuleKind::Exact, RuleKind::Timing, RuleKind::Steps, RuleKind::StepRate, RuleKind::PwmDuty}) {
        const auto result = compare_timelines(steps(100, 400), steps(100, 400), rule(k));
        EXPECT_TRUE(result.passed) << to_string(k) << "\n" << result.report();
    }
}

TEST(TimelineCompare, ExactNamesTheFirstDivergentEdge) {
    // Step 40 (0-based) rises 31 cycles late: the 82nd change, counted from 1
    // as the text and the context both count (1: the initial 0, then 2 per step).
    const auto result = compare_timelines(steps(100, 400), steps(100, 400, 40, 31), rule(RuleKind::Exact));
    ASSERT_FALSE(result.passed);
    const ChannelResult* first = result.first_divergence();
    ASSERT_NE(first, nullptr);
    EXPECT_EQ(first->signal, "uno.PD2");
    EXPECT_EQ(first->divergence_cycle, 1000u + 40 * 400);  // the golden edge, the earlier of the two
    EXPECT_EQ(first->expected, "1 at cycle 17000 (0.001062500 s)");  // 17000 / 16 MHz
    EXPECT_EQ(first->actual.rfind("1 at cycle 17031 ", 0), 0u) << first->actual;
    const std::string report = result.report();
    EXPECT_NE(report.find("first divergence: uno.PD2 at 0.001062500 s (cycle 17000): change #82 differs"), std::string::npos) << report;
    EXPECT_NE(report.find("> #82"), std::string::npos) << report;  // context marks the same change
    EXPECT_NE(report.find("uno.PD2"), std::string::npos);
}

TEST(TimelineCompare, EveryDifferingChannelGetsItsTimeAndMatchingOnesAreCounted) {
    // Golden: PD2 and PD3 step trains and a UART byte stream; actual: PD2 as
    // before, PD3's 10th step (0-based) 31 cycles late, the UART's 2nd byte
    // '\n' instead of 'k'.
    Timeline golden, actual;
    for (Timeline* t : {&golden, &actual}) {
        const SignalId pd2 = t->add_signal({"uno", "PD2", SignalKind::Wire, 1, 16000000});
        const SignalId pd3 = t->add_signal({"uno", "PD3", SignalKind::Wire, 1, 16000000});
        const SignalId tx = t->add_signal({"uno", "uart0_tx", SignalKind::Bus, 8, 16000000});
        for (int i = 0; i < 20; ++i) {
            const Cycle at = 1000 + 400 * static_cast<Cycle>(i);
            t->record(pd2, at, 1);
            t->record(pd2, at + 100, 0);
            const Cycle late = (t == &actual && i == 10) ? 31 : 0;
            t->record(pd3, at + late, 1);
            t->record(pd3, at + late + 100, 0);
        }
        t->record(tx, 50000, 'o');
        t->record(tx, 51360, t == &actual ? '\n' : 'k');
    }
    const auto result = compare_timelines(golden, actual, rule(RuleKind::Exact));
    const std::string report = result.report();
    // PD3 diverges at the golden edge 1000 + 400 * 10 = 5000 cycles (312.5 us),
    // the UART at 51360 cycles (3.21 ms); both are listed with their time.
    EXPECT_NE(report.find("0.000312500 s (cycle 5000)"), std::string::npos) << report;
    EXPECT_NE(report.find("0.003210000 s (cycle 51360)"), std::string::npos) << report;
    EXPECT_NE(report.find("0x0a '\\n' at cycle 51360"), std::string::npos) << report;  // bytes printed one way
    EXPECT_EQ(report.find("uno.PD2 "), std::string::npos) << report;  // the matching channel is not listed...
    EXPECT_NE(report.find("1 other channel matches"), std::string::npos) << report;  // ...only counted
}

TEST(TimelineCompare, TimingToleranceIsAbsolutePlusRelativeToTheInterval) {
    // The shifted pulse (rise and fall) comes 31 cycles late: its rise ends a
    // 368-cycle low interval 31 cycles long, the next rise a 31-cycle short one.
    const Timeline golden = steps(100, 400), actual = steps(100, 400, 40, 31);
    EXPECT_FALSE(compare_timelines(golden, actual, rule(RuleKind::Timing, 30)).passed);
    EXPECT_TRUE(compare_timelines(golden, actual, rule(RuleKind::Timing, 31)).passed);
    // 10 % of the 368-cycle interval before it = 36.8 cycles allowed.
    EXPECT_TRUE(compare_timelines(golden, actual, rule(RuleKind::Timing, 0, 0.10)).passed);
    EXPECT_FALSE(compare_timelines(golden, actual, rule(RuleKind::Timing, 0, 0.08)).passed);  // 29.4 < 31
}

TEST(TimelineCompare, StepsTolerateJitterButNeverALostStep) {
    const Timeline golden = steps(100, 400);
    EXPECT_TRUE(compare_timelines(golden, steps(100, 400, 40, 3), rule(RuleKind::Steps, 5)).passed);
    const auto lost = compare_timelines(golden, steps(100, 400, 0, 0, 70), rule(RuleKind::Steps, 1000));
    ASSERT_FALSE(lost.passed);
    EXPECT_NE(lost.channels[0].detail.find("100 steps expected, 99 taken (lost steps)"), std::string::npos)
        << lost.channels[0].detail;
    const auto extra = compare_timelines(golden, steps(101, 400), rule(RuleKind::Steps, 1000));
    ASSERT_FALSE(extra.passed);
    EXPECT_NE(extra.channels[0].detail.find("extra steps"), std::string::npos);
}

TEST(TimelineCompare, PwmDutyPerWindow) {
    // 25 % vs 30 % duty: period 1000 cycles, high 250 vs 300.
    auto pwm = [](Cycle high) {
        Timeline t;
        const SignalId id = t.add_signal({"mega", "PB4", SignalKind::Wire, 1, kHz});
        for (Cycle c = 0; c < 160000; c += 1000) {
            t.record(id, c, 1);
            t.record(id, c + high, 0);
        }
        return t;
    };
    CompareOptions o = rule(RuleKind::PwmDuty);
    o.rules[0].window_s = 0.001;  // 16000 cycles = 16 periods per window
    o.rules[0].band = 0.04;
    EXPECT_TRUE(compare_timelines(pwm(250), pwm(270), o).passed);   // |0.25 - 0.27| = 0.02
    EXPECT_FALSE(compare_timelines(pwm(250), pwm(300), o).passed);  // |0.25 - 0.30| = 0.05
}

TEST(TimelineCompare, BandOnRealValues) {
    auto temps = [](double offset) {
        Timeline t;
        const SignalId id = t.add_signal({"hotend", "temperature_degC", SignalKind::Real, 1, kHz});
        for (int i = 0; i < 100; ++i) t.record_real(id, static_cast<Cycle>(i) * 16000, 25.0 + i * 1.75 + offset);
        return t;
    };
    CompareOptions o = rule(RuleKind::Band);
    o.rules[0].band = 0.5;
    EXPECT_TRUE(compare_timelines(temps(0), temps(0.4), o).passed);
    EXPECT_FALSE(compare_timelines(temps(0), temps(0.6), o).passed);
}

// A golden checks what it holds: a channel it lacks is noted (a golden written
// before a board gained a net, or before the bench recorded a signal, keeps
// working); a channel it holds and the run lacks fails.
TEST(TimelineCompare, MissingChannelsFailNewOnesAreNoted) {
    Timeline golden = steps(10, 400);
    Timeline actual = steps(10, 400);
    actual.add_signal({"uno", "PD3", SignalKind::Wire, 1, kHz});
    const auto extra = compare_timelines(golden, actual, {});
    EXPECT_TRUE(extra.passed);
    EXPECT_EQ(extra.channels.back().verdict, "new");
    EXPECT_NE(extra.report().find("1 channel recorded now and not in the golden (not checked; avrbench golden update "
                                  "adds them): uno.PD3"),
              std::string::npos)
        << extra.report();
    const auto missing = compare_timelines(actual, golden, {});
    EXPECT_FALSE(missing.passed);
    EXPECT_EQ(missing.channels.back().verdict, "missing");
}

TEST(TimelineCompare, RulesMatchByGlobFirstMatchWins) {
    EXPECT_TRUE(glob_match("uno.PD*", "uno.PD2"));
    EXPECT_TRUE(glob_match("*.position_mm", "x.position_mm"));
    EXPECT_FALSE(glob_match("uno.PD?", "uno.PD10"));
    CompareOptions o;
    o.rules.push_back({"uno.PD2", RuleKind::Ignore});
    o.rules.push_back({"*", RuleKind::Exact});
    EXPECT_TRUE(compare_timelines(steps(100, 400), steps(100, 400, 40, 31), o).passed);
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// One wire recorded under two names (the MCU pin and the driver's STEP
// input on its net), both 3 cycles late at one step.
Timeline one_wire_two_names(Cycle shift_by) {
    Timeline t;
    const SignalId pin = t.add_signal({"uno", "PD2", SignalKind::Wire, 1, kHz});
    const SignalId input = t.add_signal({"x_driver", "step", SignalKind::Wire, 1, kHz});
    for (const SignalId id : {pin, input}) {
        t.record(id, 0, 0);
        for (int i = 0; i < 10; ++i) {
            const Cycle at = 1000 + static_cast<Cycle>(i) * 400 + (i == 5 ? shift_by : 0);
            t.record(id, at, 1);
            t.record(id, at + 32, 0);
        }
    }
    return t;
}

// Issue 36: a tolerance written for uno.PD2 covers x_driver.step and
// nets.x_step, the same electrical wire.
TEST(TimelineCompare, ATolerancesBelongsToTheWireNotToOneOfItsNames) {
    CompareOptions o;
    ChannelRule r;
    r.pattern = "uno.PD2";
    r.kind = RuleKind::Steps;
    r.tolerance_cycles = 4;
    o.rules.push_back(r);
    const auto without_wires = compare_timelines(one_wire_two_names(0), one_wire_two_names(3), o);
    EXPECT_FALSE(without_wires.passed) << "x_driver.step falls back to exact";
    o.wires = {{"nets.x_step", "uno.PD2", "x_driver.step"}};
    const auto with_wires = compare_timelines(one_wire_two_names(0), one_wire_two_names(3), o);
    EXPECT_TRUE(with_wires.passed) << with_wires.report();
    for (const auto& c : with_wires.channels) EXPECT_EQ(c.rule, RuleKind::Steps) << c.signal;
    // The same rule written with the net's name.
    o.rules[0].pattern = "nets.x_step";
    EXPECT_TRUE(compare_timelines(one_wire_two_names(0), one_wire_two_names(3), o).passed);
}

}  // namespace
}  // namespace avrbench
