#include "verify/Scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/Errors.hpp"
#include "core/FileHash.hpp"
#include "core/Units.hpp"
#include "parts/StepDirDriver.hpp"
#include "trace/HtmlReport.hpp"
#include "trace/TimelineText.hpp"
#include "trace/VcdWriter.hpp"
#include "verify/Bench.hpp"

namespace fs = std::filesystem;

namespace avrbench {
namespace {

std::string where(const std::string& path, const YAML::Node& node) {
    return path + ":" + std::to_string(node.Mark().line + 1);
}

std::string scalar(const YAML::Node& node, const std::string& path, const std::string& what) {
    if (!node.IsScalar()) throw BadInput(where(path, node) + ": " + what + " must be a single value");
    return node.Scalar();
}

std::string resolve(const std::string& scenario_path, const std::string& relative) {
    if (relative.empty() || fs::path(relative).is_absolute()) return relative;
    return (fs::path(scenario_path).parent_path() / relative).lexically_normal().string();
}

// Steps and expectations are one-key maps: "- delay: 10ms" or "- pin: {pin: ..., level: 0}".
template <class T>
T parse_item(const YAML::Node& item, const std::string& path, const std::set<std::string>& kinds, const char* what) {
    if (!item.IsMap() || item.size() != 1) {
        throw BadInput(where(path, item) + ": each " + what + " is one 'kind: value' entry");
    }
    T out;
    const auto kv = *item.begin();
    out.kind = kv.first.Scalar();
    out.location = where(path, kv.first);
    if (kinds.count(out.kind) == 0) {
        std::string list;
        for (const auto& k : kinds) list += (list.empty() ? "" : ", ") + k;
        throw BadInput(out.location + ": unknown " + what + " '" + out.kind + "' (known: " + list + ")");
    }
    if (kv.second.IsScalar()) {
        out.args["value"] = kv.second.Scalar();
    } else if (kv.second.IsMap()) {
        for (const auto& a : kv.second) out.args[a.first.Scalar()] = scalar(a.second, path, a.first.Scalar());
    } else if (kv.second.IsSequence()) {
        if constexpr (std::is_same_v<T, ScenarioExpectation>) {
            for (const auto& e : kv.second) out.list.push_back(scalar(e, path, "list entry"));
        } else {
            throw BadInput(out.location + ": '" + out.kind + "' takes a value or a map");
        }
    }
    return out;
}

const std::string& arg(const std::map<std::string, std::string>& args, const std::string& key,
                       const std::string& location, const std::string& kind) {
    auto it = args.find(key);
    if (it == args.end()) throw BadInput(location + ": '" + kind + "' needs '" + key + "'");
    return it->second;
}

RuleKind parse_rule(const std::string& text, const std::string& location) {
    for (RuleKind k : {RuleKind::Exact, RuleKind::Timing, RuleKind::Steps, RuleKind::StepRate, RuleKind::PwmDuty,
                       RuleKind::Band, RuleKind::Ignore}) {
        if (text == to_string(k)) return k;
    }
    throw BadInput(location + ": unknown rule '" + text + "' (exact, timing, steps, step-rate, pwm-duty, band, ignore)");
}

bool parse_level(const std::string& text, const std::string& location) {
    if (text == "0" || text == "low") return false;
    if (text == "1" || text == "high") return true;
    throw BadInput(location + ": level '" + text + "' is not 0/low or 1/high");
}

// The part of the run's timeline that the golden holds.
Timeline golden_view(const Timeline& all, const std::vector<std::string>& globs) {
    Timeline out;
    std::vector<long> map(all.signals().size(), -1);
    for (SignalId id = 0; id < all.signals().size(); ++id) {
        const SignalInfo& s = all.signals()[id];
        bool keep = false;
        if (globs.empty()) {
            keep = s.kind != SignalKind::Real;
        } else {
            for (const auto& g : globs) keep = keep || glob_match(g, s.scope + "." + s.name);
        }
        if (keep) map[id] = static_cast<long>(out.add_signal(s));
    }
    for (const auto& e : all.events()) {
        if (map[e.signal] < 0) continue;
        TimelineEvent copy = e;
        copy.signal = static_cast<SignalId>(map[e.signal]);
        if (all.signals()[e.signal].kind == SignalKind::Real) {
            out.record_real(copy.signal, copy.cycle, copy.value.real);
        } else {
            out.record(copy.signal, copy.cycle, copy.value.bits);
        }
    }
    return out;
}

}  // namespace

ScenarioSpec load_scenario(const std::string& path, const std::string& firmware_dir) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw BadInput(path + ": no such scenario file");
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    YAML::Node root;
    try {
        root = YAML::Load(ss.str());
    } catch (const YAML::Exception& e) {
        throw BadInput(path + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
    }
    if (!root.IsMap()) throw BadInput(path + ":1: a scenario is a map with board, firmware, steps, expect");
    static const std::set<std::string> kKeys = {"name", "description", "board", "firmware", "time_limit",
                                                "steps", "expect", "golden", "golden_signals", "tolerances"};
    for (const auto& kv : root) {
        if (kKeys.count(kv.first.Scalar()) == 0) {
            throw BadInput(where(path, kv.first) + ": unknown key '" + kv.first.Scalar() +
                           "' (expected name, description, board, firmware, time_limit, steps, expect, golden, tolerances)");
        }
    }
    ScenarioSpec spec;
    spec.path = path;
    spec.name = root["name"] ? scalar(root["name"], path, "name") : fs::path(path).stem().string();
    if (root["description"]) spec.description = scalar(root["description"], path, "description");
    if (!root["board"]) throw BadInput(path + ":1: the scenario needs 'board'");
    spec.board_path = resolve(path, scalar(root["board"], path, "board"));
    if (!root["firmware"] || !root["firmware"].IsMap()) {
        throw BadInput(path + ":1: the scenario needs 'firmware: {mcu: name-or-path}'");
    }
    for (const auto& kv : root["firmware"]) {
        std::string value = scalar(kv.second, path, "firmware");
        const bool bare_name = value.find('/') == std::string::npos && value.find(".elf") == std::string::npos;
        value = bare_name ? (fs::path(firmware_dir) / (value + ".elf")).string() : resolve(path, value);
        if (!fs::is_regular_file(value, ec)) throw BadInput(where(path, kv.second) + ": firmware " + value + ": no such file");
        spec.firmware[kv.first.Scalar()] = value;
    }
    if (root["time_limit"]) {
        spec.time_limit_s = parse_seconds(scalar(root["time_limit"], path, "time_limit"), where(path, root["time_limit"]) + ": time_limit");
    }
    static const std::set<std::string> kSteps = {"wait_for_text", "send", "send_file", "wait_idle", "wait_pin",
                                                 "delay", "set_input", "release_input", "inject_fault"};
    if (root["steps"]) {
        for (const auto& item : root["steps"]) {
            ScenarioStep step = parse_item<ScenarioStep>(item, path, kSteps, "step");
            if (step.kind == "send_file") step.args["value"] = resolve(path, arg(step.args, "value", step.location, step.kind));
            spec.steps.push_back(step);
        }
    }
    static const std::set<std::string> kExpect = {"steps", "position", "pin", "text", "findings"};
    if (root["expect"]) {
        for (const auto& item : root["expect"]) spec.expectations.push_back(parse_item<ScenarioExpectation>(item, path, kExpect, "expectation"));
    }
    if (root["golden"]) spec.golden_path = resolve(path, scalar(root["golden"], path, "golden"));
    if (root["golden_signals"]) {
        for (const auto& g : root["golden_signals"]) spec.golden_signals.push_back(scalar(g, path, "golden_signals entry"));
    }
    if (root["tolerances"]) {
        for (const auto& t : root["tolerances"]) {
            const std::string loc = where(path, t);
            if (!t.IsMap()) throw BadInput(loc + ": a tolerance is a map {signals, rule, ...}");
            ChannelRule rule;
            for (const auto& kv : t) {
                const std::string key = kv.first.Scalar();
                const std::string value = scalar(kv.second, path, key);
                if (key == "signals") rule.pattern = value;
                else if (key == "rule") rule.kind = parse_rule(value, loc);
                else if (key == "cycles") rule.tolerance_cycles = parse_quantity(value, Dimension::Dimensionless, loc + ": cycles");
                else if (key == "relative") rule.tolerance_rel = parse_quantity(value, Dimension::Dimensionless, loc + ": relative");
                else if (key == "window") rule.window_s = parse_seconds(value, loc + ": window");
                else if (key == "band") rule.band = parse_quantity(value, Dimension::Dimensionless, loc + ": band");
                else throw BadInput(loc + ": unknown tolerance key '" + key + "' (signals, rule, cycles, relative, window, band)");
            }
            spec.tolerances.push_back(rule);
        }
    }
    return spec;
}

std::string ScenarioResult::text() const {
    std::string out = (passed ? "PASS " : "FAIL ") + name + "\n";
    for (const auto& f : failures) out += "  " + f + "\n";
    if (comparison && !comparison->passed) out += "\n" + comparison->report();
    if (!report_path.empty()) out += "  report: " + report_path + "\n";
    return out;
}

ScenarioResult run_scenario(const ScenarioSpec& spec, const ScenarioRunOptions& options) {
    ScenarioResult result;
    result.name = spec.name;
    const auto wall_start = std::chrono::steady_clock::now();
    Bench bench(spec.board_path, spec.firmware);
    bench.trace_board();
    const double deadline = spec.time_limit_s;
    auto fail = [&](const std::string& message) { result.failures.push_back(message); };

    std::size_t step_index = 0;
    for (const auto& step : spec.steps) {
        ++step_index;
        const std::string here = "step " + std::to_string(step_index) + " (" + step.location + ", " + step.kind + ")";
        const auto& a = step.args;
        bool ok = true;
        if (step.kind == "send") {
            bench.host().add_line(arg(a, "value", step.location, step.kind));
        } else if (step.kind == "send_file") {
            bench.host().load_file(arg(a, "value", step.location, step.kind));
        } else if (step.kind == "delay") {
            const double d = parse_seconds(arg(a, "value", step.location, step.kind), step.location + ": delay");
            bench.run_for(std::min(d, std::max(0.0, deadline - bench.now_seconds())));
        } else if (step.kind == "wait_idle") {
            const auto settle_it = a.find("value");
            const double settle = settle_it != a.end() ? parse_seconds(settle_it->second, step.location + ": wait_idle") : 0.05;
            const IdleResult r = bench.run_until_idle(std::max(0.0, deadline - bench.now_seconds()), settle);
            if (r != IdleResult::Idle) {
                std::string why = to_string(r);
                if (r == IdleResult::HostFailed) why += ": " + bench.host().failure_message();
                fail(here + ": not idle within the time limit (" + why + ")");
                ok = false;
            }
        } else if (step.kind == "wait_for_text") {
            const std::string& text = arg(a, "value", step.location, step.kind);
            UartHost& host = bench.host();
            bool found = false;
            std::size_t checked = 0;
            while (!found) {
                const auto& transcript = host.transcript();
                for (; checked < transcript.size(); ++checked) {
                    if (transcript[checked].direction == Direction::Received &&
                        transcript[checked].text.find(text) != std::string::npos) {
                        found = true;
                    }
                }
                if (found) break;
                if (bench.now_seconds() >= deadline || host.failed()) break;
                if (bench.board().run_until_seconds(std::min(deadline, bench.now_seconds() + 1e-4)) == StopReason::Halted) break;
            }
            if (!found) {
                fail(here + ": the firmware sent no line containing '" + text + "' within " + std::to_string(deadline) + " s");
                ok = false;
            }
        } else if (step.kind == "wait_pin") {
            Pin& pin = bench.board().pin(arg(a, "pin", step.location, step.kind));
            const bool level = parse_level(arg(a, "level", step.location, step.kind), step.location);
            while (pin.level() != level && bench.now_seconds() < deadline) {
                if (bench.board().run_until_seconds(std::min(deadline, bench.now_seconds() + 1e-5)) == StopReason::Halted) break;
            }
            if (pin.level() != level) {
                fail(here + ": " + pin.name() + " did not become " + (level ? "1" : "0") + " in time");
                ok = false;
            }
        } else if (step.kind == "set_input") {
            bench.board().pin(arg(a, "pin", step.location, step.kind)).drive(parse_level(arg(a, "level", step.location, step.kind), step.location));
        } else if (step.kind == "release_input") {
            bench.board().pin(arg(a, "value", step.location, step.kind)).release();
        } else if (step.kind == "inject_fault") {
            Part& part = bench.board().part(arg(a, "part", step.location, step.kind));
            part.inject_fault(arg(a, "fault", step.location, step.kind), part.clock().cycle());
        }
        if (!ok) break;
    }

    // Expectations.
    std::vector<Finding> findings = bench.findings();
    for (const auto& e : spec.expectations) {
        const auto& a = e.args;
        const std::string here = "expect " + e.kind + " (" + e.location + ")";
        char buf[256];
        if (e.kind == "steps") {
            Axis& axis = bench.axis(arg(a, "axis", e.location, e.kind));
            const auto want = static_cast<std::uint64_t>(parse_quantity(arg(a, "count", e.location, e.kind), Dimension::Dimensionless, e.location));
            if (axis.steps() != want) {
                std::snprintf(buf, sizeof buf, ": axis %s took %llu steps, expected %llu", axis.name().c_str(),
                              static_cast<unsigned long long>(axis.steps()), static_cast<unsigned long long>(want));
                fail(here + buf);
            }
        } else if (e.kind == "position") {
            Axis& axis = bench.axis(arg(a, "axis", e.location, e.kind));
            const double want = parse_quantity(arg(a, "mm", e.location, e.kind), Dimension::Dimensionless, e.location);
            const double within = a.count("within") ? parse_quantity(a.at("within"), Dimension::Dimensionless, e.location) : 1e-6;
            if (std::fabs(axis.position_mm() - want) > within) {
                std::snprintf(buf, sizeof buf, ": axis %s at %.6f mm, expected %.6f +- %g", axis.name().c_str(),
                              axis.position_mm(), want, within);
                fail(here + buf);
            }
        } else if (e.kind == "pin") {
            Pin& pin = bench.board().pin(arg(a, "pin", e.location, e.kind));
            const bool level = parse_level(arg(a, "level", e.location, e.kind), e.location);
            if (pin.level() != level) fail(here + ": " + pin.name() + " is " + (pin.level() ? "1" : "0"));
        } else if (e.kind == "text") {
            const std::string& text = arg(a, "value", e.location, e.kind);
            if (bench.host().received_text().find(text) == std::string::npos) {
                fail(here + ": the firmware never sent '" + text + "'");
            }
        } else if (e.kind == "findings") {
            std::multiset<std::string> got;
            for (const auto& f : findings) got.insert(to_string(f.kind));
            if (e.list.empty()) {
                const auto want = static_cast<std::size_t>(parse_quantity(arg(a, "value", e.location, e.kind), Dimension::Dimensionless, e.location));
                if (findings.size() != want) {
                    std::string list;
                    for (const auto& f : findings) list += "\n      " + f.describe();
                    fail(here + ": " + std::to_string(findings.size()) + " findings, expected " + std::to_string(want) + list);
                }
            } else {
                std::multiset<std::string> want(e.list.begin(), e.list.end());
                if (got != want) {
                    std::string g;
                    for (const auto& k : got) g += (g.empty() ? "" : ", ") + k;
                    fail(here + ": findings are [" + g + "]");
                }
            }
        }
    }

    // Golden timeline.
    Mcu& first = bench.mcu();
    TimelineHeader header;
    header.bench_version = AVRBENCH_VERSION;
    // Paths relative to the scenario and file names, so a golden reads the
    // same on every machine; the hashes say which inputs made it (the ELF's
    // changes with its build directory through debug info, so it informs
    // rather than decides).
    for (const auto& [mcu, elf] : spec.firmware) {
        header.inputs.push_back({"firmware." + mcu, sha256_of_file(elf), fs::path(elf).filename().string()});
    }
    header.inputs.push_back({"board", sha256_of_file(spec.board_path),
                             fs::relative(spec.board_path, fs::path(spec.path).parent_path()).string()});
    header.inputs.push_back({"stimulus", sha256_of_file(spec.path), fs::path(spec.path).filename().string()});
    for (const auto& step : spec.steps) {
        if (step.kind == "send_file") {
            header.inputs.push_back({"stimulus.file", sha256_of_file(step.args.at("value")),
                                     fs::relative(step.args.at("value"), fs::path(spec.path).parent_path()).string()});
        }
    }
    header.end_cycle = first.cycle();
    header.end_clock_hz = first.frequency_hz();
    const Timeline actual = golden_view(bench.timeline(), spec.golden_signals);
    if (!spec.golden_path.empty()) {
        if (options.update_golden) {
            fs::create_directories(fs::path(spec.golden_path).parent_path());
            write_timeline_text(actual, header, spec.golden_path);
        } else if (!fs::exists(spec.golden_path)) {
            fail("golden: no golden timeline at " + spec.golden_path + " (create it with: avrbench golden update " + spec.path + ")");
        } else {
            const ParsedTimeline golden = read_timeline_text(spec.golden_path);
            CompareOptions compare;
            compare.rules = spec.tolerances;
            compare.golden_end_cycle = golden.header.end_cycle;
            compare.actual_end_cycle = header.end_cycle;
            result.comparison = compare_timelines(golden.timeline, actual, compare);
            if (!result.comparison->passed) {
                const ChannelResult* d = result.comparison->first_divergence();
                fail("golden: " + (d ? d->signal + " diverges at " + std::to_string(d->seconds() * 1e3) + " ms: " + d->detail
                                     : std::string("channels differ")));
            }
        }
    }

    result.simulated_s = bench.now_seconds();
    result.passed = result.failures.empty();
    if (!options.report_dir.empty()) {
        fs::create_directories(options.report_dir);
        RunReport report = bench.make_report(spec.name);
        report.facts.push_back("scenario: " + spec.path);
        report.facts.push_back(std::string("verdict: ") + (result.passed ? "PASS" : "FAIL"));
        for (const auto& f : result.failures) report.facts.push_back(f);
        if (result.comparison) {
            ComparisonView view;
            view.passed = result.comparison->passed;
            view.golden = read_timeline_text(spec.golden_path).timeline;
            if (const ChannelResult* d = result.comparison->first_divergence()) {
                view.first_divergence_signal = d->signal;
                view.first_divergence_cycle = d->divergence_cycle;
                view.first_divergence_clock_hz = d->clock_hz;
            }
            view.summary = result.comparison->report();
            for (const auto& c : result.comparison->channels) view.channels.push_back({c.signal, c.verdict, c.detail});
            report.comparison = std::move(view);
        }
        result.report_path = (fs::path(options.report_dir) / (spec.name + ".html")).string();
        write_html_report(report, result.report_path);
    }
    result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    return result;
}

namespace {
std::string xml_escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '&': out += "&amp;"; break;
            case '"': out += "&quot;"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t') {
                    out += ' ';
                } else {
                    out += c;
                }
        }
    }
    return out;
}
}  // namespace

std::string junit_xml(const std::vector<ScenarioResult>& results, const std::string& suite_name) {
    std::size_t failures = 0;
    double total = 0;
    for (const auto& r : results) {
        failures += r.passed ? 0 : 1;
        total += r.wall_s;
    }
    char buf[256];
    std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    std::snprintf(buf, sizeof buf, "<testsuite name=\"%s\" tests=\"%zu\" failures=\"%zu\" errors=\"0\" time=\"%.3f\">\n",
                  xml_escape(suite_name).c_str(), results.size(), failures, total);
    out += buf;
    for (const auto& r : results) {
        std::snprintf(buf, sizeof buf, "  <testcase classname=\"avrbench.scenario\" name=\"%s\" time=\"%.3f\"",
                      xml_escape(r.name).c_str(), r.wall_s);
        out += buf;
        if (r.passed) {
            out += "/>\n";
            continue;
        }
        out += ">\n    <failure message=\"" + xml_escape(r.failures.empty() ? "failed" : r.failures.front()) + "\">" +
               xml_escape(r.text()) + "</failure>\n  </testcase>\n";
    }
    out += "</testsuite>\n";
    return out;
}

}  // namespace avrbench
