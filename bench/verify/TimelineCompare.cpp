#include "verify/TimelineCompare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "trace/SignalChanges.hpp"

namespace avrbench {
namespace {

std::string full_name(const SignalInfo& s) { return s.scope + "." + s.name; }

std::string value_text(const SignalInfo& info, const TimelineEvent& e) {
    char buf[64];
    if (info.kind == SignalKind::Real) {
        std::snprintf(buf, sizeof buf, "%.6g", e.value.real);
    } else if (info.kind == SignalKind::Bus && info.width == 8) {
        // Bytes one way: hex, then the character as a C literal would write it.
        const auto b = static_cast<unsigned>(e.value.bits & 0xff);
        char shown[8];
        switch (b) {
            case '\n': std::snprintf(shown, sizeof shown, "\\n"); break;
            case '\r': std::snprintf(shown, sizeof shown, "\\r"); break;
            case '\t': std::snprintf(shown, sizeof shown, "\\t"); break;
            case '\'': std::snprintf(shown, sizeof shown, "\\'"); break;
            case '\\': std::snprintf(shown, sizeof shown, "\\\\"); break;
            default:
                if (b >= 0x20 && b < 0x7f) std::snprintf(shown, sizeof shown, "%c", static_cast<char>(b));
                else std::snprintf(shown, sizeof shown, "\\x%02x", b);
        }
        std::snprintf(buf, sizeof buf, "0x%02x '%s'", b, shown);
    } else {
        std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(e.value.bits));
    }
    return buf;
}

std::string event_text(const SignalInfo& info, const TimelineEvent& e) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s at cycle %llu (%.9f s)", value_text(info, e).c_str(),
                  static_cast<unsigned long long>(e.cycle), static_cast<double>(e.cycle) / info.clock_hz);
    return buf;
}

bool equal_value(const SignalInfo& info, const TimelineEvent& a, const TimelineEvent& b) {
    return info.kind == SignalKind::Real ? a.value.real == b.value.real : a.value.bits == b.value.bits;
}

void add_context(ChannelResult& r, const SignalInfo& info, const SignalChanges& g,
                 const SignalChanges& a, std::size_t index, std::size_t around) {
    const std::size_t from = index > around ? index - around : 0;
    const std::size_t to = std::min(std::max(g.size(), a.size()), index + around + 1);
    for (std::size_t i = from; i < to; ++i) {
        std::string line = (i == index ? "> " : "  ") + std::string("#") + std::to_string(i + 1) + "  golden ";
        line += i < g.size() ? event_text(info, g[i]) : "(none)";
        line += "  |  actual ";
        line += i < a.size() ? event_text(info, a[i]) : "(none)";
        r.context.push_back(line);
    }
}

void diverge_at(ChannelResult& r, const SignalInfo& info, const SignalChanges& g,
                const SignalChanges& a, std::size_t index, std::size_t around, const std::string& detail) {
    r.passed = false;
    r.verdict = "differs";
    r.diverges = true;
    r.detail = detail;
    const bool have_g = index < g.size(), have_a = index < a.size();
    r.divergence_cycle = have_g && have_a ? std::min(g[index].cycle, a[index].cycle)
                         : have_g         ? g[index].cycle
                                          : a[index].cycle;
    r.expected = have_g ? event_text(info, g[index]) : "(no more changes)";
    r.actual = have_a ? event_text(info, a[index]) : "(no more changes)";
    add_context(r, info, g, a, index, around);
}

// A wire's rising edges (not a high level at cycle 0), each with value 1.
SignalChanges rising(const SignalChanges& changes) {
    SignalChanges out(SignalKind::Wire);
    for (std::size_t i = 0; i < changes.size(); ++i) {
        if (changes.bits(i) != 0 && (i > 0 || changes.cycle(i) > 0)) out.add(changes.cycle(i), 1);
    }
    return out;
}

// Walks a piecewise-constant signal forward in time: each event is visited
// a bounded number of times however many queries, so a comparison costs
// O(events + windows), not their product.
class Cursor {
public:
    Cursor(const SignalChanges& changes, const SignalInfo& info) : c_(changes), info_(info) {}

    // The value at `cycle` (0 before the first change); `cycle` must not decrease between calls.
    double value_at(Cycle cycle) {
        while (i_ < c_.size() && c_[i_].cycle <= cycle) {
            value_ = info_.kind == SignalKind::Real ? c_[i_].value.real : static_cast<double>(c_[i_].value.bits);
            level_ = c_[i_].value.bits != 0;
            ++i_;
        }
        return value_;
    }

    // Fraction of [begin, end) during which a wire is high; windows in order.
    double duty(Cycle begin, Cycle end) {
        if (end <= begin) return 0;
        value_at(begin);
        Cycle high = 0, t = begin;
        bool level = level_;
        for (std::size_t j = i_; j < c_.size() && c_[j].cycle < end; ++j) {
            if (level) high += c_[j].cycle - t;
            t = c_[j].cycle;
            level = c_[j].value.bits != 0;
        }
        if (level) high += end - t;
        return static_cast<double>(high) / static_cast<double>(end - begin);
    }

    // Events in [begin, end); windows in order.
    std::size_t count(Cycle begin, Cycle end) {
        while (k_ < c_.size() && c_[k_].cycle < begin) ++k_;
        std::size_t j = k_;
        while (j < c_.size() && c_[j].cycle < end) ++j;
        return j - k_;
    }

private:
    const SignalChanges& c_;
    const SignalInfo& info_;
    std::size_t i_ = 0, k_ = 0;
    double value_ = 0;
    bool level_ = false;
};

// Exact: every change at the same cycle with the same value.
void compare_exact(ChannelResult& r, const SignalInfo& info, const SignalChanges& g,
                   const SignalChanges& a, std::size_t around) {
    char buf[200];
    for (std::size_t i = 0; i < std::max(g.size(), a.size()); ++i) {
        if (i < g.size() && i < a.size() && g[i].cycle == a[i].cycle && equal_value(info, g[i], a[i])) continue;
        std::snprintf(buf, sizeof buf, "change #%zu differs (%zu golden vs %zu actual changes)", i + 1, g.size(), a.size());
        diverge_at(r, info, g, a, i, around, buf);
        return;
    }
}

// Timing: the same values, each edge within the tolerance of its place or
// its interval within the tolerance of its length.
void compare_timing(ChannelResult& r, const SignalInfo& info, const ChannelRule& rule, const SignalChanges& g,
                   const SignalChanges& a, std::size_t around) {
    char buf[200];
    double worst = 0;
    for (std::size_t i = 0; i < std::max(g.size(), a.size()); ++i) {
        if (i >= g.size() || i >= a.size() || !equal_value(info, g[i], a[i])) {
            std::snprintf(buf, sizeof buf, "change #%zu: value sequence differs (%zu golden vs %zu actual changes)",
                          i + 1, g.size(), a.size());
            diverge_at(r, info, g, a, i, around, buf);
            return;
        }
        // Either the edge is where it was (absolute tolerance), or the
        // interval that ends at it is as long as it was (relative
        // tolerance): a jittered pulse moves its edges but keeps its width.
        const double shift = std::fabs(static_cast<double>(a[i].cycle) - static_cast<double>(g[i].cycle));
        const double g_interval = static_cast<double>(i == 0 ? g[0].cycle : g[i].cycle - g[i - 1].cycle);
        const double a_interval = static_cast<double>(i == 0 ? a[0].cycle : a[i].cycle - a[i - 1].cycle);
        const double interval_error = std::fabs(a_interval - g_interval);
        const double interval_allowed = rule.tolerance_cycles + rule.tolerance_rel * g_interval;
        worst = std::max(worst, shift);
        if (shift > rule.tolerance_cycles && interval_error > interval_allowed) {
            std::snprintf(buf, sizeof buf,
                          "change #%zu moved by %.0f cycles (tolerance %.0f); its interval changed by %.0f "
                          "(tolerance %.1f)",
                          i + 1, shift, rule.tolerance_cycles, interval_error, interval_allowed);
            diverge_at(r, info, g, a, i, around, buf);
            return;
        }
    }
    std::snprintf(buf, sizeof buf, "largest shift %.0f cycles", worst);
    r.detail = buf;
}

// Steps: the rising edges, each within the tolerance, and as many.
void compare_steps(ChannelResult& r, const SignalInfo& info, const ChannelRule& rule, const SignalChanges& g,
                   const SignalChanges& a, std::size_t around) {
    char buf[200];
    const auto gs = rising(g), as = rising(a);
    double worst = 0;
    for (std::size_t i = 0; i < std::min(gs.size(), as.size()); ++i) {
        const double shift = std::fabs(static_cast<double>(as[i].cycle) - static_cast<double>(gs[i].cycle));
        worst = std::max(worst, shift);
        if (shift > rule.tolerance_cycles) {
            std::snprintf(buf, sizeof buf, "step #%zu moved by %.0f cycles, tolerance %.0f", i + 1, shift,
                          rule.tolerance_cycles);
            diverge_at(r, info, gs, as, i, around, buf);
            return;
        }
    }
    if (gs.size() != as.size()) {
        std::snprintf(buf, sizeof buf, "%zu steps expected, %zu taken (%s)", gs.size(), as.size(),
                      as.size() < gs.size() ? "lost steps" : "extra steps");
        diverge_at(r, info, gs, as, std::min(gs.size(), as.size()), around, buf);
        return;
    }
    std::snprintf(buf, sizeof buf, "%zu steps, largest shift %.0f cycles", gs.size(), worst);
    r.detail = buf;
}

// Band: both signals' values at every change of either, within the band.
void compare_band(ChannelResult& r, const SignalInfo& info, const ChannelRule& rule, const SignalChanges& g,
                  const SignalChanges& a) {
    char buf[200];
    // Both signals at every time either changes, in time order (a merge of two sorted lists).
    Cursor cg(g, info), ca(a, info);
    double worst = 0;
    std::size_t ig = 0, ia = 0;
    while (ig < g.size() || ia < a.size()) {
        const bool take_g = ia >= a.size() || (ig < g.size() && g[ig].cycle <= a[ia].cycle);
        const Cycle t = take_g ? g[ig++].cycle : a[ia++].cycle;
        const double vg = cg.value_at(t), va = ca.value_at(t);
        const double d = std::fabs(va - vg);
        worst = std::max(worst, d);
        if (d > rule.band) {
            std::snprintf(buf, sizeof buf, "at %.9f s actual %.6g vs golden %.6g (band %.6g)",
                          static_cast<double>(t) / info.clock_hz, va, vg, rule.band);
            r.passed = false;
            r.verdict = "differs";
            r.diverges = true;
            r.divergence_cycle = t;
            r.detail = buf;
            std::snprintf(buf, sizeof buf, "%.6g", vg);
            r.expected = buf;
            std::snprintf(buf, sizeof buf, "%.6g", va);
            r.actual = buf;
            return;
        }
    }
    std::snprintf(buf, sizeof buf, "largest difference %.6g", worst);
    r.detail = buf;
}

// PwmDuty and StepRate: window by window up to the earlier run's end.
void compare_windows(ChannelResult& r, const SignalInfo& info, const ChannelRule& rule, const SignalChanges& g,
                     const SignalChanges& a, Cycle end) {
    char buf[200];
    const Cycle window = std::max<Cycle>(1, static_cast<Cycle>(std::llround(rule.window_s * info.clock_hz)));
    const auto gs = rising(g), as = rising(a);
    Cursor duty_g(g, info), duty_a(a, info), steps_g(gs, info), steps_a(as, info);
    for (Cycle begin = 0; begin < end; begin += window) {
        const Cycle stop = std::min(end, begin + window);
        if (rule.kind == RuleKind::PwmDuty) {
            const double dg = duty_g.duty(begin, stop), da = duty_a.duty(begin, stop);
            if (std::fabs(dg - da) > rule.band) {
                std::snprintf(buf, sizeof buf, "duty %.4f vs golden %.4f in the window at %.6f s (band %.4f)", da,
                              dg, static_cast<double>(begin) / info.clock_hz, rule.band);
                r.passed = false;
                r.verdict = "differs";
                r.diverges = true;
                r.divergence_cycle = begin;
                r.detail = buf;
                r.expected = std::to_string(dg);
                r.actual = std::to_string(da);
                return;
            }
        } else {
            const auto cg = static_cast<double>(steps_g.count(begin, stop));
            const auto ca = static_cast<double>(steps_a.count(begin, stop));
            if (std::fabs(ca - cg) > rule.tolerance_rel * cg + 1) {
                std::snprintf(buf, sizeof buf, "%.0f steps vs golden %.0f in the window at %.6f s", ca, cg,
                              static_cast<double>(begin) / info.clock_hz);
                r.passed = false;
                r.verdict = "differs";
                r.diverges = true;
                r.divergence_cycle = begin;
                r.detail = buf;
                r.expected = std::to_string(static_cast<long long>(cg));
                r.actual = std::to_string(static_cast<long long>(ca));
                return;
            }
        }
    }
    r.detail = "all windows within tolerance";
}

void compare_channel(ChannelResult& r, const SignalInfo& info, const ChannelRule& rule,
                     const SignalChanges& g, const SignalChanges& a,
                     const CompareOptions& options) {
    const std::size_t around = options.context_events;
    switch (rule.kind) {
        case RuleKind::Ignore: return;
        case RuleKind::Exact: return compare_exact(r, info, g, a, around);
        case RuleKind::Timing: return compare_timing(r, info, rule, g, a, around);
        case RuleKind::Steps: return compare_steps(r, info, rule, g, a, around);
        case RuleKind::Band: return compare_band(r, info, rule, g, a);
        case RuleKind::StepRate:
        case RuleKind::PwmDuty: {
            const Cycle g_end = options.golden_end_cycle ? options.golden_end_cycle : (g.empty() ? 0 : g.back().cycle);
            const Cycle a_end = options.actual_end_cycle ? options.actual_end_cycle : (a.empty() ? 0 : a.back().cycle);
            return compare_windows(r, info, rule, g, a, std::min(g_end, a_end));
        }
    }
}

}  // namespace

const char* to_string(RuleKind kind) {
    switch (kind) {
        case RuleKind::Exact: return "exact";
        case RuleKind::Timing: return "timing";
        case RuleKind::Steps: return "steps";
        case RuleKind::StepRate: return "step-rate";
        case RuleKind::PwmDuty: return "pwm-duty";
        case RuleKind::Band: return "band";
        case RuleKind::Ignore: return "ignore";
    }
    return "?";
}

bool glob_match(const std::string& pattern, const std::string& text) {
    std::size_t p = 0, t = 0, star = std::string::npos, mark = 0;
    while (t < text.size()) {
        if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == text[t])) {
            ++p;
            ++t;
        } else if (p < pattern.size() && pattern[p] == '*') {
            star = p++;
            mark = t;
        } else if (star != std::string::npos) {
            p = star + 1;
            t = ++mark;
        } else {
            return false;
        }
    }
    while (p < pattern.size() && pattern[p] == '*') ++p;
    return p == pattern.size();
}

const ChannelResult* CompareResult::first_divergence() const {
    const ChannelResult* first = nullptr;
    for (const auto& c : channels) {
        if (c.passed || !c.diverges) continue;
        if (first == nullptr || c.seconds() < first->seconds()) first = &c;
    }
    if (first == nullptr) {
        for (const auto& c : channels) {
            if (!c.passed) return &c;
        }
    }
    return first;
}

namespace {

// The first rule whose pattern matches the signal or another name of its wire.
ChannelRule rule_for(const std::string& signal, const CompareOptions& options,
                     const std::map<std::string, const std::vector<std::string>*>& wire_of) {
    const auto wire = wire_of.find(signal);
    for (const auto& candidate : options.rules) {
        if (glob_match(candidate.pattern, signal)) return candidate;
        if (wire == wire_of.end()) continue;
        for (const auto& other : *wire->second) {
            if (glob_match(candidate.pattern, other)) return candidate;
        }
    }
    return ChannelRule{};
}

}  // namespace

ChannelRule rule_for_signal(const std::string& signal, const CompareOptions& options) {
    std::map<std::string, const std::vector<std::string>*> wire_of;
    for (const auto& wire : options.wires) {
        for (const auto& name : wire) wire_of[name] = &wire;
    }
    return rule_for(signal, options, wire_of);
}

CompareResult compare_timelines(const Timeline& golden, const Timeline& actual, const CompareOptions& options) {
    return compare_changes(timeline_changes(golden), timeline_changes(actual), options);
}

CompareResult compare_changes(const TimelineChanges& golden, const TimelineChanges& actual, const CompareOptions& options) {
    CompareResult result;
    std::map<std::string, const std::vector<std::string>*> wire_of;
    for (const auto& wire : options.wires) {
        for (const auto& name : wire) wire_of[name] = &wire;
    }
    const auto& golden_changes = golden.changes;
    const auto& actual_changes = actual.changes;
    std::map<std::string, SignalId> actual_ids;
    for (SignalId id = 0; id < actual.signals.size(); ++id) actual_ids[full_name(actual.signals[id])] = id;
    std::map<std::string, bool> seen;
    for (SignalId gid = 0; gid < golden.signals.size(); ++gid) {
        const SignalInfo& info = golden.signals[gid];
        ChannelResult r;
        r.signal = full_name(info);
        r.clock_hz = info.clock_hz;
        r.verdict = "ok";
        seen[r.signal] = true;
        const ChannelRule rule = rule_for(r.signal, options, wire_of);
        r.rule = rule.kind;
        const auto& g = golden_changes[gid];
        r.golden_changes = g.size();
        auto it = actual_ids.find(r.signal);
        if (it == actual_ids.end()) {
            if (rule.kind != RuleKind::Ignore) {
                r.passed = false;
                r.verdict = "missing";
                r.detail = "the run did not record this signal";
                if (!g.empty()) {
                    r.diverges = true;
                    r.divergence_cycle = g.front().cycle;
                }
            }
            result.channels.push_back(r);
            continue;
        }
        const auto& a = actual_changes[it->second];
        r.actual_changes = a.size();
        compare_channel(r, info, rule, g, a, options);
        result.channels.push_back(r);
    }
    for (const auto& [name, id] : actual_ids) {
        if (seen.count(name)) continue;
        const ChannelRule rule = rule_for(name, options, wire_of);
        if (rule.kind == RuleKind::Ignore) continue;
        ChannelResult r;
        r.signal = name;
        r.rule = rule.kind;
        // A golden checks the channels it holds. One recorded now that it does
        // not hold (a net added to the board, a signal a newer bench records)
        // cannot contradict it: noted, not failed; `golden update` adds it.
        r.passed = true;
        r.verdict = "new";
        r.detail = "recorded now, not in the golden timeline (avrbench golden update adds it)";
        const auto& a = actual_changes[id];
        r.actual_changes = a.size();
        r.clock_hz = actual.signals[id].clock_hz;
        if (!a.empty()) {
            r.diverges = true;
            r.divergence_cycle = a.front().cycle;
        }
        result.channels.push_back(r);
    }
    for (const auto& c : result.channels) result.passed = result.passed && c.passed;
    return result;
}

std::string CompareResult::report() const {
    std::string out;
    std::size_t failing = 0;
    for (const auto& c : channels) failing += c.passed ? 0 : 1;
    char buf[512];
    std::vector<std::string> fresh;
    for (const auto& c : channels) {
        if (c.verdict == "new") fresh.push_back(c.signal);
    }
    std::string fresh_note;
    if (!fresh.empty()) {
        fresh_note = std::to_string(fresh.size()) + " channel" + (fresh.size() == 1 ? "" : "s") +
                     " recorded now and not in the golden (not checked; avrbench golden update adds them):";
        for (const auto& name : fresh) fresh_note += " " + name;
        fresh_note += "\n";
    }
    if (passed) {
        std::snprintf(buf, sizeof buf, "PASS: all %zu channels the golden holds match it\n", channels.size() - fresh.size());
        return buf + fresh_note;
    }
    std::snprintf(buf, sizeof buf, "FAIL: %zu of %zu channels differ from the golden timeline\n", failing, channels.size());
    out += buf;
    if (const ChannelResult* first = first_divergence()) {
        std::snprintf(buf, sizeof buf, "first divergence: %s at %.9f s (cycle %llu): %s\n", first->signal.c_str(),
                      first->seconds(), static_cast<unsigned long long>(first->divergence_cycle), first->detail.c_str());
        out += buf;
        if (!first->expected.empty() || !first->actual.empty()) {
            out += "  expected " + first->expected + "\n";
            out += "  actual   " + first->actual + "\n";
        }
        for (const auto& line : first->context) out += "  " + line + "\n";
    }
    // Every differing channel with its own first divergence, earliest first;
    // the channels that match are counted, not listed.
    std::vector<const ChannelResult*> differing;
    for (const auto& c : channels) {
        if (!c.passed) differing.push_back(&c);
    }
    std::stable_sort(differing.begin(), differing.end(), [](const ChannelResult* a, const ChannelResult* b) {
        if (a->diverges != b->diverges) return a->diverges;
        return a->seconds() < b->seconds();
    });
    out += "\n";
    std::snprintf(buf, sizeof buf, "%-28s %-9s %-8s %9s %9s  %-32s %s\n", "channel", "rule", "verdict", "golden", "actual",
                  "diverges at", "detail");
    out += buf;
    for (const ChannelResult* c : differing) {
        char at[64] = "-";
        if (c->diverges) {
            std::snprintf(at, sizeof at, "%.9f s (cycle %llu)", c->seconds(), static_cast<unsigned long long>(c->divergence_cycle));
        }
        std::snprintf(buf, sizeof buf, "%-28s %-9s %-8s %9zu %9zu  %-32s %s\n", c->signal.c_str(), to_string(c->rule),
                      c->verdict.c_str(), c->golden_changes, c->actual_changes, at, c->detail.c_str());
        out += buf;
        if (!c->expected.empty() || !c->actual.empty()) out += "    expected " + c->expected + "; actual " + c->actual + "\n";
    }
    const std::size_t matching = channels.size() - failing - fresh.size();
    std::snprintf(buf, sizeof buf, "%zu other channel%s match%s\n", matching, matching == 1 ? "" : "s",
                  matching == 1 ? "es" : "");
    out += buf;
    return out + fresh_note;
}

}  // namespace avrbench
