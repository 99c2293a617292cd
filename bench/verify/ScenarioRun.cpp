// Running a loaded scenario: its steps on a Bench, then its expectations,
// then the golden comparison (or update), then the optional HTML report.
#include <chrono>
#include <fstream>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "core/FileHash.hpp"
#include "core/UserStop.hpp"
#include "mcu/TimingProfile.hpp"
#include "core/VectorNames.hpp"
#include "trace/WaveformFiles.hpp"
#include "trace/HtmlReport.hpp"
#include "core/OutputFile.hpp"
#include "trace/TimelineText.hpp"
#include "run/Bench.hpp"
#include "core/TextPattern.hpp"
#include "verify/Scenario.hpp"

namespace fs = std::filesystem;

namespace avrbench {
namespace {

// Whether the golden holds a signal: those its globs name, or without
// globs every signal but the real-valued ones.
bool in_golden(const SignalInfo& s, const std::vector<std::string>& globs) {
    if (globs.empty()) return s.kind != SignalKind::Real;
    for (const auto& g : globs) {
        if (glob_match(g, s.scope + "." + s.name)) return true;
    }
    return false;
}

// The part of the run's timeline that the golden holds.
Timeline golden_view(const Timeline& all, const std::vector<std::string>& globs) {
    Timeline out;
    std::vector<long> map(all.signals().size(), -1);
    for (SignalId id = 0; id < all.signals().size(); ++id) {
        const SignalInfo& s = all.signals()[id];
        if (in_golden(s, globs)) map[id] = static_cast<long>(out.add_signal(s));
    }
    for (const auto& e : all.events()) {
        if (map[e.signal] < 0) continue;
        const auto id = static_cast<SignalId>(map[e.signal]);
        if (all.signals()[e.signal].kind == SignalKind::Real) {
            out.record_real(id, e.cycle, e.value.real);
        } else {
            out.record(id, e.cycle, e.value.bits);
        }
    }
    return out;
}

std::string seconds_text(Picoseconds ps) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.6f s", seconds_from_ps(ps));
    return buf;
}

// A path as seen from `base_dir`, the same whatever the working directory.
std::string relative_to(const std::string& path, const fs::path& base_dir) {
    std::error_code ec;
    const fs::path rel = fs::relative(fs::absolute(path, ec), fs::absolute(base_dir, ec), ec);
    return ec || rel.empty() ? fs::path(path).filename().string() : rel.generic_string();
}

// Every name each board net is recorded under: its endpoints ("uno.PD2",
// "x_driver.step"), "nets.<net>" and "labels.<label>" for labels on it.
std::vector<std::vector<std::string>> wire_names(const BoardSpec& spec) {
    std::vector<std::vector<std::string>> wires;
    for (const auto& net : spec.nets) {
        std::vector<std::string> names{"nets." + net.name};
        for (const auto& e : net.endpoints) names.push_back(e.text());
        for (const auto& label : spec.labels) {
            for (const auto& e : net.endpoints) {
                if (label.endpoint.text() == e.text()) names.push_back("labels." + label.name);
            }
        }
        wires.push_back(std::move(names));
    }
    return wires;
}

// A run whose timeline nothing needs whole (no report, no debugger): the
// timeline streams its events here and holds none itself. The golden's
// signals are kept as each signal's changes for the comparison (8 bytes a
// wire change instead of a timeline's 24 and its copies), and the VCD of
// `--vcd-dir` is written as the run goes.
class StreamedRun {
public:
    // `golden_globs`: the golden's signals, or nullptr without a golden;
    // `vcd_path`: "" for no waveform files.
    StreamedRun(Bench& bench, const std::vector<std::string>* golden_globs, const std::string& vcd_path)
        : bench_(bench), timeline_(bench.timeline()), golden_globs_(golden_globs) {
        if (!vcd_path.empty()) {
            // The VCD's own timeline: the run's signals and names, fed from the stream.
            vcd_timeline_ = std::make_unique<Timeline>(timeline_);
            vcd_timeline_->take_events();
            std::vector<std::string> mcu_scopes;
            for (Mcu* m : bench.board().mcus()) mcu_scopes.push_back(m->name());
            files_ = std::make_unique<WaveformFiles>(*vcd_timeline_, vcd_path, true, VcdOptions{}, mcu_scopes);
            files_->start();
        }
        timeline_.stream_to([this](const std::vector<TimelineEvent>& events) { take(events); });
    }
    StreamedRun(const StreamedRun&) = delete;
    StreamedRun& operator=(const StreamedRun&) = delete;
    ~StreamedRun() { timeline_.stream_to(nullptr); }

    bool keeps_golden() const { return golden_globs_ != nullptr; }

    // The run's changes of the golden's signals, once the run is over (once:
    // what is recorded later is not kept).
    TimelineChanges golden_changes() {
        timeline_.flush_stream();
        map_signals();
        for (auto& c : golden_.changes) c.finish();
        golden_globs_ = nullptr;
        return std::move(golden_);
    }
    // Ends the VCD (and writes its save file) once the run is over; its path.
    std::string finish_vcd() {
        timeline_.flush_stream();
        const std::string path = files_->vcd_path();
        files_->finish(bench_.mcu().cycle(), bench_.mcu().frequency_hz());
        return path;
    }

private:
    // Signals registered since the last batch (a board may add them as it runs).
    void map_signals() {
        if (golden_globs_ == nullptr) return;
        const auto& signals = timeline_.signals();
        for (SignalId id = static_cast<SignalId>(map_.size()); id < signals.size(); ++id) {
            if (!in_golden(signals[id], *golden_globs_)) {
                map_.push_back(-1);
                continue;
            }
            map_.push_back(static_cast<long>(golden_.signals.size()));
            golden_.signals.push_back(signals[id]);
            golden_.changes.emplace_back(signals[id].kind);
        }
    }
    void take(const std::vector<TimelineEvent>& events) {
        map_signals();
        if (golden_globs_ != nullptr) {
            for (const TimelineEvent& e : events) {
                if (e.signal < map_.size() && map_[e.signal] >= 0) golden_.changes[static_cast<std::size_t>(map_[e.signal])].add(e);
            }
        }
        if (files_) {
            for (const TimelineEvent& e : events) {
                if (timeline_.signals()[e.signal].kind == SignalKind::Real) {
                    vcd_timeline_->record_real(e.signal, e.cycle, e.value.real);
                } else {
                    vcd_timeline_->record(e.signal, e.cycle, e.value.bits);
                }
            }
            files_->drain(bench_.now_ps());
        }
    }

    Bench& bench_;
    Timeline& timeline_;
    const std::vector<std::string>* golden_globs_;
    std::vector<long> map_;  // timeline SignalId -> index in golden_, or -1
    TimelineChanges golden_;
    std::unique_ptr<Timeline> vcd_timeline_;
    std::unique_ptr<WaveformFiles> files_;
};

class StepRunner {
public:
    StepRunner(Bench& bench, Picoseconds deadline_ps) : bench_(bench), deadline_(deadline_ps) {}

    // Runs one step; returns "" or why it failed.
    std::string run(const ScenarioStep& step) {
        return std::visit([this](const auto& action) { return (*this)(action); }, step.action);
    }

private:
    std::string operator()(const SendStep& s) {
        bench_.host().add_line(s.line);
        return "";
    }
    std::string operator()(const SendFileStep& s) {
        bench_.host().load_file(s.path);
        return "";
    }
    std::string operator()(const DelayStep& s) {
        const Picoseconds end = std::min(deadline_, add_ps(bench_.now_ps(), s.duration_ps));
        return bench_.run_to_ps(end, {}) == IdleResult::Interrupted ? "interrupted (SIGINT/SIGTERM)" : "";
    }
    std::string operator()(const WaitIdleStep& s) {
        const Picoseconds now = bench_.now_ps();
        const IdleResult r = bench_.run_until_idle_ps(deadline_ - std::min(deadline_, now), s.settle_ps);
        if (r == IdleResult::Idle) return "";
        std::string why = to_string(r);
        if (r == IdleResult::HostFailed) why += ": " + bench_.host().failure_message();
        return "not idle within the time limit (" + why + ")";
    }
    std::string operator()(const WaitForTextStep& s) {
        UartHost& host = bench_.host();
        for (const auto& entry : host.transcript()) {
            if (entry.direction == Direction::Received && entry.text.find(s.text) != std::string::npos) return "";
        }
        // Woken by the line itself: the run stops after the instruction that
        // completed it, at its exact cycle. The listener outlives the step
        // (a host keeps its listeners); `waiting` makes it inert afterwards.
        auto waiting = std::make_shared<bool>(true);
        auto seen = std::make_shared<bool>(false);
        Board& board = bench_.board();
        host.on_line_received([waiting, seen, &board, text = s.text](const TranscriptEntry& entry) {
            if (!*waiting || entry.direction != Direction::Received || entry.text.find(text) == std::string::npos) return;
            *seen = true;
            board.request_stop();
        });
        // Each pass either returns or runs the board to a later time (core/Time.hpp).
        while (!*seen) {
            const Picoseconds now = bench_.now_ps();
            if (now >= deadline_ || host.failed() || user_stop_requested() || bench_.timeline().overflowed()) break;
            if (bench_.board().run_until_ps(std::min(deadline_, add_ps(now, kGuardSlicePs))) == StopReason::Halted) break;
        }
        *waiting = false;
        if (*seen) return "";
        return "the firmware sent no line containing '" + s.text + "' by " + seconds_text(deadline_) +
               " (the time limit)";
    }
    std::string operator()(const WaitPinStep& s) {
        Pin& pin = bench_.board().pin(s.pin);
        // Woken by the edge itself, at its exact cycle (as the text wait).
        auto waiting = std::make_shared<bool>(true);
        Board& board = bench_.board();
        pin.on_change([waiting, &board, level = s.level](Cycle, bool now) {
            if (*waiting && now == level) board.request_stop();
        });
        while (pin.level() != s.level) {
            const Picoseconds now = bench_.now_ps();
            if (now >= deadline_ || user_stop_requested() || bench_.timeline().overflowed()) break;
            if (bench_.board().run_until_ps(std::min(deadline_, add_ps(now, kGuardSlicePs))) == StopReason::Halted) break;
        }
        *waiting = false;
        if (pin.level() == s.level) return "";
        return s.pin + " did not become " + (s.level ? "1" : "0") + " by " + seconds_text(deadline_) + " (the time limit)";
    }
    std::string operator()(const SetInputStep& s) {
        bench_.board().drive_pin(s.pin, s.level);
        return "";
    }
    std::string operator()(const ReleaseInputStep& s) {
        bench_.board().release_pin(s.pin);
        return "";
    }
    std::string operator()(const InjectFaultStep& s) {
        Part& part = bench_.board().part(s.part);
        part.inject_fault(s.fault, part.clock().cycle());
        return "";
    }
    std::string operator()(const PartActionStep& s) {
        bench_.board().part(s.part).act(s.action, s.arguments);
        return "";
    }

    // Waits wake on their event; slices only bound how long a SIGINT or a
    // full recorder goes unnoticed.
    static constexpr Picoseconds kGuardSlicePs = 10 * kPsPerMs;
    Bench& bench_;
    Picoseconds deadline_;
};

// What a `signal` expectation saw of its signal while the steps ran: the
// value in force when its window opened and the extremes after.
struct SignalWatch {
    bool found = false;
    std::string known;  // the part's signals, for the message when not found
    std::size_t index = 0;
    Cycle from_cycle = 0;
    double clock_hz = 1;
    double before = 0;  // the last value before from_cycle (the initial one at first)
    bool changed_after = false;
    double low = 0, high = 0;
    Cycle low_at = 0, high_at = 0;
};
using SignalWatches = std::map<const ExpectSignal*, std::shared_ptr<SignalWatch>>;

SignalWatches watch_expected_signals(Bench& bench, const std::vector<ScenarioExpectation>& expectations) {
    SignalWatches watches;
    for (const auto& e : expectations) {
        const auto* sig = std::get_if<ExpectSignal>(&e.action);
        if (sig == nullptr) continue;
        auto w = std::make_shared<SignalWatch>();
        watches[sig] = w;
        Part& part = bench.board().part(sig->part);
        for (const auto& info : part.signals()) w->known += (w->known.empty() ? "" : ", ") + info.name;
        const auto index = part.signal_index(sig->signal);
        if (!index) continue;
        w->found = true;
        w->index = *index;
        w->clock_hz = part.clock().frequency_hz();
        w->from_cycle = part.clock().cycles_from_seconds(seconds_from_ps(sig->from_ps));
        w->before = part.signal_value(w->index);
        part.watch_signals([w](std::size_t signal, Cycle cycle, double value) {
            if (signal != w->index) return;
            if (cycle < w->from_cycle) {
                w->before = value;
                return;
            }
            if (!w->changed_after || value < w->low) w->low = value, w->low_at = cycle;
            if (!w->changed_after || value > w->high) w->high = value, w->high_at = cycle;
            w->changed_after = true;
        });
    }
    return watches;
}

class ExpectationChecker {
public:
    ExpectationChecker(Bench& bench, const std::vector<Finding>& findings, const SignalWatches& watches)
        : bench_(bench), findings_(findings), watches_(watches) {}
    std::string check(const ScenarioExpectation& e) {
        return std::visit([this](const auto& action) { return (*this)(action); }, e.action);
    }

private:
    std::string operator()(const ExpectSteps& e) {
        Axis& axis = bench_.axis(e.axis);
        if (axis.steps() == e.count) return "";
        return "axis " + e.axis + " took " + std::to_string(axis.steps()) + " steps, expected " + std::to_string(e.count);
    }
    std::string operator()(const ExpectPosition& e) {
        Axis& axis = bench_.axis(e.axis);
        const double at = axis.rotary() ? axis.position_deg() : axis.position_mm();
        if (std::fabs(at - e.value) <= e.within) return "";
        char buf[200];
        std::snprintf(buf, sizeof buf, "axis %s at %.6f %s, expected %.6f +- %g", e.axis.c_str(), at,
                      axis.rotary() ? "deg" : "mm", e.value, e.within);
        return buf;
    }
    std::string operator()(const ExpectPin& e) {
        Pin& pin = bench_.board().pin(e.pin);
        if (pin.level() == e.level) return "";
        return e.pin + " is " + (pin.level() ? "1" : "0");
    }
    std::string operator()(const ExpectText& e) {
        if (bench_.host().received_text().find(e.text) != std::string::npos) return "";
        return "the firmware never sent '" + e.text + "'";
    }
    std::string operator()(const ExpectLcdShows& e) {
        const Part::TextReadout* shown = bench_.board().part(e.part).find_text_readout("lines");
        if (shown == nullptr) return "part " + e.part + " shows no text";
        const std::vector<std::string> lines = shown->lines();
        const TextPattern pattern(e.pattern, "lcd_shows");
        std::string text;
        if (e.line > 0) {
            text = static_cast<std::size_t>(e.line) <= lines.size() ? lines[static_cast<std::size_t>(e.line - 1)] : "";
        } else {
            for (const auto& l : lines) text += (text.empty() ? "" : "\n") + l;
        }
        if (pattern.found_in(text)) return "";
        std::string screen;
        for (const auto& l : lines) screen += "|" + l + "|";
        return e.part + (e.line > 0 ? " line " + std::to_string(e.line) : std::string()) + " does not show /" + e.pattern +
               "/; it shows " + screen;
    }
    std::string operator()(const ExpectSignal& e) {
        const SignalWatch& w = *watches_.at(&e);
        const std::string name = e.part + "." + e.signal;
        if (!w.found) return "part " + e.part + " has no signal '" + e.signal + "' (it has " + w.known + ")";
        const Picoseconds end = bench_.now_ps();
        if (end < e.from_ps) return "the run ended at " + seconds_text(end) + ", before " + seconds_text(e.from_ps);
        // The value in force at `from`, then every change after it.
        double low = w.before, high = w.before;
        Cycle low_at = w.from_cycle, high_at = w.from_cycle;
        if (w.changed_after && w.low < low) low = w.low, low_at = w.low_at;
        if (w.changed_after && w.high > high) high = w.high, high_at = w.high_at;
        char buf[240];
        if (e.min && low < *e.min) {
            std::snprintf(buf, sizeof buf, "%s went down to %g at %.6f s, below %g (from %s on)", name.c_str(), low,
                          static_cast<double>(low_at) / w.clock_hz, *e.min, seconds_text(e.from_ps).c_str());
            return buf;
        }
        if (e.max && high > *e.max) {
            std::snprintf(buf, sizeof buf, "%s went up to %g at %.6f s, above %g (from %s on)", name.c_str(), high,
                          static_cast<double>(high_at) / w.clock_hz, *e.max, seconds_text(e.from_ps).c_str());
            return buf;
        }
        return "";
    }
    const TimingProfiler& profile(const std::string& mcu) {
        return *(mcu.empty() ? bench_.mcu() : bench_.mcu(mcu)).profile();
    }
    std::string operator()(const ExpectIsr& e) {
        const auto& vectors = profile(e.mcu).vectors();
        const auto it = vectors.find(e.vector);
        const Mcu& m = e.mcu.empty() ? bench_.mcu() : bench_.mcu(e.mcu);
        const std::string label = vector_name(m.mcu_type(), e.vector);
        const std::string name = "vector " + std::to_string(e.vector) + (label.empty() ? "" : " (" + label + ")");
        if (it == vectors.end() || it->second.runs == 0) {
            return e.min_runs && *e.min_runs == 0 ? "" : name + " never ran";
        }
        // Every bound it breaks, not only the first.
        const VectorProfile& v = it->second;
        std::vector<std::string> broken;
        if (e.min_runs && v.runs < *e.min_runs) {
            broken.push_back("ran " + std::to_string(v.runs) + " times, expected at least " + std::to_string(*e.min_runs));
        }
        if (e.max_cycles && v.inclusive_cycles.max() > *e.max_cycles) {
            broken.push_back("took up to " + std::to_string(v.inclusive_cycles.max()) + " cycles (median " +
                             std::to_string(v.inclusive_cycles.median()) + "), expected at most " + std::to_string(*e.max_cycles));
        }
        if (e.max_latency_cycles && v.latency_cycles.max() > *e.max_latency_cycles) {
            broken.push_back("started up to " + std::to_string(v.latency_cycles.max()) + " cycles after its flag, expected at most " +
                             std::to_string(*e.max_latency_cycles));
        }
        if (broken.empty()) return "";
        std::string text = name;
        for (std::size_t i = 0; i < broken.size(); ++i) text += (i == 0 ? " " : "; and ") + broken[i];
        return text;
    }
    std::string operator()(const ExpectStack& e) {
        const Mcu& m = e.mcu.empty() ? bench_.mcu() : bench_.mcu(e.mcu);
        const std::int64_t headroom = static_cast<std::int64_t>(profile(e.mcu).lowest_sp()) + 1 -
                                      static_cast<std::int64_t>(m.elf().ram_end_of_static_data());
        if (headroom >= e.min_headroom_bytes) return "";
        return "the stack came within " + std::to_string(headroom) + " bytes of .bss/.noinit, expected at least " +
               std::to_string(e.min_headroom_bytes);
    }
    std::string operator()(const ExpectInterruptsOff& e) {
        const TimingProfiler& p = profile(e.mcu);
        if (p.longest_interrupts_off() <= e.max_cycles) return "";
        return "interrupts were off for " + std::to_string(p.longest_interrupts_off()) + " cycles, expected at most " +
               std::to_string(e.max_cycles);
    }
    std::string operator()(const ExpectCpu& e) {
        const Mcu& m = e.mcu.empty() ? bench_.mcu() : bench_.mcu(e.mcu);
        const TimingProfiler& p = profile(e.mcu);
        const double total = static_cast<double>(p.active_cycles() + p.sleeping_cycles() + m.idle_cycles_skipped());
        const double busy = total > 0 ? 100.0 * static_cast<double>(p.active_cycles()) / total : 0.0;
        if (busy <= e.max_busy_percent) return "";
        char text[160];
        std::snprintf(text, sizeof text, "the CPU executed %.2f%% of the time, expected at most %g%%", busy, e.max_busy_percent);
        return text;
    }
    std::string operator()(const ExpectFindingCount& e) {
        if (findings_.size() == e.count) return "";
        std::string list;
        for (const auto& f : findings_) list += "\n      " + f.describe();
        return std::to_string(findings_.size()) + " findings, expected " + std::to_string(e.count) + list;
    }
    std::string operator()(const ExpectFindingKinds& e) {
        std::multiset<std::string> got, want(e.kinds.begin(), e.kinds.end());
        for (const auto& f : findings_) got.insert(to_string(f.kind));
        if (got == want) return "";
        std::string g;
        for (const auto& k : got) g += (g.empty() ? "" : ", ") + k;
        return "findings are [" + g + "]";
    }

    Bench& bench_;
    const std::vector<Finding>& findings_;
    const SignalWatches& watches_;
};

// Checks what only the built board can say (fault names), before anything runs.
void bind(const ScenarioSpec& spec, Bench& bench) {
    for (const auto& step : spec.steps) {
        if (const auto* a = std::get_if<PartActionStep>(&step.action)) {
            const Part& part = bench.board().part(a->part);
            const auto actions = part.actions();
            const bool known = std::any_of(actions.begin(), actions.end(), [&](const Part::Action& x) { return x.name == a->action; });
            if (!known) {
                std::string list;
                for (const auto& x : actions) list += (list.empty() ? "" : ", ") + x.name;
                throw BadInput(step.location + ": part '" + a->part + "' (" + std::string(part.type()) + ") cannot " + a->action +
                               " (actions: " + (list.empty() ? "none" : list) + ")");
            }
        }
        if (const auto* f = std::get_if<InjectFaultStep>(&step.action)) {
            const Part& part = bench.board().part(f->part);
            const auto names = part.fault_names();
            if (f->fault != "none" && std::find(names.begin(), names.end(), f->fault) == names.end()) {
                std::string list = "none";
                for (const auto& n : names) list += ", " + n;
                throw BadInput(step.location + ": part '" + f->part + "' (" + std::string(part.type()) + ") has no fault '" +
                               f->fault + "' (faults: " + list + ")");
            }
        }
    }
}

TimelineHeader golden_header(const ScenarioSpec& spec, const Mcu& first) {
    TimelineHeader header;
    header.bench_version = AVRBENCH_VERSION;
    // Paths relative to the scenario's folder, so a golden reads the same
    // whatever the working directory; the hashes say which inputs made it.
    const fs::path base = fs::absolute(spec.path).parent_path();
    for (const auto& [mcu, elf] : spec.firmware) {
        header.inputs.push_back({"firmware." + mcu, sha256_of_file(elf), fs::path(elf).filename().string()});
    }
    header.inputs.push_back({"board", sha256_of_file(spec.board_path), relative_to(spec.board_path, base)});
    header.inputs.push_back({"stimulus", sha256_of_file(spec.path), fs::path(spec.path).filename().string()});
    for (const auto& file : spec.stimulus_files()) {
        header.inputs.push_back({"stimulus.file", sha256_of_file(file), relative_to(file, base)});
    }
    header.end_cycle = first.cycle();
    header.end_clock_hz = first.frequency_hz();
    return header;
}

// `golden update` writes only a golden timeline, and only where goldens
// live: a file named *.timeline inside the scenario's own folder tree, or
// inside a folder named `golden` beside the scenario's folder or one of its
// parents (tests/scenarios/x.yaml -> ../../golden/x.timeline); a file that is
// already there must be a golden timeline. So a scenario, whoever wrote it,
// can never make `golden update` overwrite another file.
void check_golden_writable(const ScenarioSpec& spec) {
    const std::string where = spec.path + ": golden " + escaped(spec.golden_path);
    const fs::path golden = fs::weakly_canonical(fs::absolute(spec.golden_path));
    if (golden.extension() != ".timeline") throw BadInput(where + ": golden update writes only files named *.timeline");
    const fs::path scenario_folder = fs::weakly_canonical(fs::absolute(spec.path)).parent_path();
    const auto inside = [](const fs::path& file, const fs::path& folder) {
        const auto [f, d] = std::mismatch(file.begin(), file.end(), folder.begin(), folder.end());
        return d == folder.end() && f != file.end();
    };
    bool allowed = inside(golden, scenario_folder);
    for (fs::path folder = scenario_folder; !allowed; folder = folder.parent_path()) {
        allowed = inside(golden, folder / "golden");
        if (folder == folder.parent_path()) break;
    }
    if (!allowed) {
        throw BadInput(where + ": golden update writes only inside the scenario's folder or a 'golden' folder beside it or "
                               "one of its parents");
    }
    std::error_code ec;
    if (fs::exists(golden, ec)) {
        std::string first_line;
        {
            std::ifstream in(golden);
            std::getline(in, first_line);
        }
        if (!fs::is_regular_file(golden, ec) || first_line.rfind("avrbench-timeline ", 0) != 0) {
            throw BadInput(where + ": the file there is not a golden timeline; golden update will not overwrite it");
        }
    }
}

// Compares the run with the golden timeline (or writes it), adding what
// differs to result.failures; returns the golden for the report.
// With `streamed`, the run's golden signals came through it and the
// timeline holds none: the golden is read as changes and not returned.
std::optional<ParsedTimeline> compare_with_golden(const ScenarioSpec& spec, const ScenarioRunOptions& options,
                                                  Bench& bench, ScenarioResult& result, StreamedRun* streamed) {
    if (spec.golden_path.empty()) return std::nullopt;
    const TimelineHeader header = golden_header(spec, bench.mcu());
    const auto run_changes = [&] {
        return streamed != nullptr ? streamed->golden_changes()
                                   : timeline_changes(golden_view(bench.timeline(), spec.golden_signals));
    };
    if (options.update_golden) {
        const TimelineChanges actual = run_changes();
        if (!result.expectation_failures.empty() && !options.force) {
            result.failures.push_back("golden: not updated, because the run failed its steps or expectations "
                                      "(use --force to write it anyway)");
        } else {
            // A steps tolerance is the jitter a constant-rate train may be
            // written with: the golden keeps its nominal period, not its jitter.
            CompareOptions rules;
            rules.rules = spec.tolerances;
            rules.wires = wire_names(bench.board().spec());
            std::map<std::string, Cycle> jitter;
            for (const SignalInfo& s : actual.signals) {
                const std::string name = s.scope + "." + s.name;
                const ChannelRule rule = rule_for_signal(name, rules);
                if (rule.kind == RuleKind::Steps && rule.tolerance_cycles >= 1) {
                    jitter[name] = static_cast<Cycle>(rule.tolerance_cycles);
                }
            }
            write_timeline_text(actual, header, spec.golden_path, jitter);
        }
        return std::nullopt;
    }
    if (!fs::exists(spec.golden_path)) {
        result.failures.push_back("golden: no golden timeline at " + spec.golden_path +
                                  " (create it with: avrbench golden update " + spec.path + ")");
        return std::nullopt;
    }
    CompareOptions compare;
    compare.rules = spec.tolerances;
    compare.wires = wire_names(bench.board().spec());
    compare.actual_end_cycle = header.end_cycle;
    // Read no further than this run went: a golden claiming more costs no more than the run.
    std::optional<ParsedTimeline> golden;
    if (streamed != nullptr) {
        const TimelineChanges actual = run_changes();
        const ParsedChanges golden_changes = read_timeline_changes(spec.golden_path, bench.now_seconds());
        compare.golden_end_cycle = golden_changes.header.end_cycle;
        result.comparison = compare_changes(golden_changes.changes, actual, compare);
    } else {
        golden = read_timeline_text(spec.golden_path, bench.now_seconds());
        compare.golden_end_cycle = golden->header.end_cycle;
        result.comparison = compare_timelines(golden->timeline, golden_view(bench.timeline(), spec.golden_signals), compare);
    }
    if (!result.comparison->passed) {
        const ChannelResult* d = result.comparison->first_divergence();
        char at[96] = "";
        if (d != nullptr) {
            std::snprintf(at, sizeof at, " diverges at %.6f s (cycle %llu): ", d->seconds(),
                          static_cast<unsigned long long>(d->divergence_cycle));
        }
        result.failures.push_back("golden: " + (d ? d->signal + at + d->detail : std::string("channels differ")));
    }
    return golden;
}

// The HTML report of a scenario: the run, its verdict and failures, and the
// comparison with its golden.
std::string write_scenario_report(const ScenarioSpec& spec, const std::string& report_dir, const Bench& bench,
                                  const ScenarioResult& result, const std::optional<ParsedTimeline>& golden) {
    RunReport report = bench.make_report(spec.name);
    report.facts.push_back("scenario: " + spec.path);
    report.facts.push_back(std::string("verdict: ") + (result.passed ? "PASS" : "FAIL"));
    for (const auto& f : result.failures) report.facts.push_back(f);
    if (result.comparison && golden) {
        ComparisonView view;
        view.passed = result.comparison->passed;
        view.golden = golden->timeline;
        if (const ChannelResult* d = result.comparison->first_divergence()) {
            view.first_divergence_signal = d->signal;
            view.first_divergence_cycle = d->divergence_cycle;
            view.first_divergence_clock_hz = d->clock_hz;
        }
        view.summary = result.comparison->report();
        for (const auto& c : result.comparison->channels) view.channels.push_back({c.signal, c.verdict, c.detail});
        report.comparison = std::move(view);
    }
    // The name was checked when the file loaded: no separators, so the
    // report stays inside report_dir.
    const std::string path = (fs::path(report_dir) / (spec.name + ".html")).string();
    write_html_report(report, path);
    return path;
}

}  // namespace

ScenarioResult run_scenario(const ScenarioSpec& spec, const ScenarioRunOptions& options) {
    ScenarioResult result;
    result.name = spec.name;
    result.path = spec.path;
    const auto wall_start = std::chrono::steady_clock::now();
    if (options.update_golden && !spec.golden_path.empty()) check_golden_writable(spec);
    Bench bench(spec.board_path, spec.firmware);
    bind(spec, bench);
    if (spec.host_family || spec.host_line_timeout_ps || spec.host_error_pattern) {
        UartHostOptions o = default_host_options(bench.serial_port());
        if (spec.host_family) o.family = parse_firmware_family(*spec.host_family, spec.path);
        if (spec.host_error_pattern) o.error_patterns.push_back(*spec.host_error_pattern);
        if (spec.host_line_timeout_ps) o.line_timeout_s = seconds_from_ps(*spec.host_line_timeout_ps);
        bench.host("", o);
    }
    bench.trace_board();
    // Unless a report or a debugger reads the run's timeline, it streams:
    // into the comparison (or the golden written) and the VCD.
    std::optional<StreamedRun> streamed;
    if ((!spec.golden_path.empty() || !options.vcd_dir.empty()) && options.report_dir.empty() && !options.prepared) {
        // The name was checked when the file loaded: the files stay inside vcd_dir.
        streamed.emplace(bench, spec.golden_path.empty() ? nullptr : &spec.golden_signals,
                         options.vcd_dir.empty() ? "" : (fs::path(options.vcd_dir) / (spec.name + ".vcd")).string());
        result.streamed = true;
    }
    // Timing bounds need the profile of the MCUs they name.
    for (const auto& e : spec.expectations) {
        std::visit(
            [&](const auto& a) {
                if constexpr (requires { a.mcu; }) (a.mcu.empty() ? bench.mcu() : bench.mcu(a.mcu)).enable_profile();
            },
            e.action);
    }
    if (options.prepared) options.prepared(bench);
    auto fail = [&](const std::string& message) {
        result.failures.push_back(message);
        result.expectation_failures.push_back(message);
    };

    const SignalWatches watches = watch_expected_signals(bench, spec.expectations);
    StepRunner runner(bench, spec.time_limit_ps);
    std::size_t index = 0;
    for (const auto& step : spec.steps) {
        ++index;
        const std::string why = runner.run(step);
        if (bench.timeline().overflowed()) break;  // ERROR below: the run can no longer be compared whole
        if (!why.empty()) {
            fail("step " + std::to_string(index) + " (" + step.location + ", " + step.kind + "): " + why);
            break;
        }
    }
    if (bench.timeline().overflowed()) throw BadInput(spec.path + ": " + bench.timeline().overflow_message());

    const std::vector<Finding> findings = bench.findings();
    ExpectationChecker checker(bench, findings, watches);
    for (const auto& e : spec.expectations) {
        const std::string why = checker.check(e);
        if (!why.empty()) fail("expect " + e.kind + " (" + e.location + "): " + why);
    }

    const std::optional<ParsedTimeline> golden =
        compare_with_golden(spec, options, bench, result, streamed && streamed->keeps_golden() ? &*streamed : nullptr);
    result.simulated_s = bench.now_seconds();
    result.passed = result.failures.empty();
    if (!options.report_dir.empty()) result.report_path = write_scenario_report(spec, options.report_dir, bench, result, golden);
    if (!options.vcd_dir.empty() && streamed) {
        result.vcd_path = streamed->finish_vcd();
    } else if (!options.vcd_dir.empty()) {
        // The name was checked when the file loaded: the files stay inside vcd_dir.
        std::vector<std::string> mcu_scopes;
        for (Mcu* m : bench.board().mcus()) mcu_scopes.push_back(m->name());
        WaveformFiles files(bench.timeline(), (fs::path(options.vcd_dir) / (spec.name + ".vcd")).string(), false, {},
                            mcu_scopes);
        files.finish(bench.mcu().cycle(), bench.mcu().frequency_hz());
        result.vcd_path = files.vcd_path();
    }
    result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    return result;
}

}  // namespace avrbench
