// Idle-loop fast-forward (mcu/IdleLoopSkip) on boards, plain run against
// skipping, medians of alternating runs of thread CPU time. Neither side
// records anything (the CLI without --vcd), so timer outputs that repeat
// reach the heaters as periodic waves on both sides (periph/timer/PeriodicOutput).
// Then the proof that skipping changes nothing: the untraced pair's end
// state (cycle, registers, I/O and RAM, every part's summary line), and a
// traced pair (every pin and part signal, as `avrbench run --vcd` records
// them) whose timelines must be identical event for event.
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

extern "C" {
#include <sim_avr.h>
}

#include "CpuTime.hpp"
#include "boards/Board.hpp"
#include "run/Bench.hpp"

namespace {

using avrbench_perf::median;
using avrbench_perf::thread_cpu_seconds;

struct Workload {
    const char* label;
    const char* board;  // bench/boards/<board>.yaml
    const char* mcu;
    const char* firmware;
    double seconds;
    double traced_seconds;
};

struct EndState {
    avrbench::Cycle cycle = 0;
    std::vector<std::uint8_t> data;
    std::vector<std::string> summaries;
    bool operator==(const EndState&) const = default;
};

struct Sample {
    double cpu_s = 0;
    EndState end;
};

Sample run_untraced(const Workload& w, const std::string& fw, const std::string& src, bool skip, double seconds) {
    const double start = thread_cpu_seconds();
    auto board = avrbench::Board::from_file(src + "/bench/boards/" + w.board + ".yaml",
                                            {{w.mcu, fw + "/" + w.firmware + ".elf"}});
    avrbench::Mcu& mcu = board->mcu(w.mcu);
    mcu.set_skip_idle_loops(skip);
    board->run_for_seconds(seconds);
    Sample s;
    s.cpu_s = thread_cpu_seconds() - start;
    mcu.settle_periodic_outputs();
    s.end.cycle = mcu.cycle();
    const avr_t* avr = mcu.avr();
    s.end.data.assign(avr->data, avr->data + avr->ramend + 1);
    for (avrbench::Part* p : board->parts()) s.end.summaries.push_back(p->name() + ": " + p->summary());
    return s;
}

// Events of a traced run: every pin, net alias, USART and part signal.
std::vector<avrbench::TimelineEvent> run_traced(const Workload& w, const std::string& fw, const std::string& src,
                                                bool skip) {
    avrbench::Bench bench(src + "/bench/boards/" + w.board + ".yaml",
                          std::map<std::string, std::string>{{w.mcu, fw + "/" + w.firmware + ".elf"}});
    bench.mcu(w.mcu).set_skip_idle_loops(skip);
    bench.trace_board();
    bench.run_for(w.traced_seconds);
    return bench.timeline().events();
}

bool same_events(const std::vector<avrbench::TimelineEvent>& a, const std::vector<avrbench::TimelineEvent>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i].cycle != b[i].cycle || a[i].signal != b[i].signal || a[i].value.bits != b[i].value.bits) return false;
    }
    return true;
}

}  // namespace

void run_fast_forward(const std::string& firmware_dir, const std::string& source_dir, int repeats, double scale) {
    const Workload workloads[] = {
        {"grbl_stepper, UNO + CNC shield, idle waiting for a line", "arduino-uno-cnc-shield-v3", "uno", "grbl_stepper",
         60.0, 5.0},
        {"heat_wait, RAMPS 1.4, waiting for temperature (Teacup-style)", "ramps-1.4", "mega", "heat_wait", 60.0, 5.0},
    };
    std::printf("\n%-64s %7s %9s %9s %7s %9s %9s\n", "idle fast-forward on boards (medians)", "sim s", "plain RTF",
                "skip RTF", "gain", "same end", "timeline");
    for (const Workload& w : workloads) {
        const double seconds = w.seconds * scale;
        std::vector<double> plain_cpu, skip_cpu;
        bool same_end = true;
        for (int r = 0; r < std::max(1, repeats); ++r) {
            const Sample plain = run_untraced(w, firmware_dir, source_dir, false, seconds);
            const Sample skip = run_untraced(w, firmware_dir, source_dir, true, seconds);
            plain_cpu.push_back(plain.cpu_s);
            skip_cpu.push_back(skip.cpu_s);
            same_end = same_end && plain.end == skip.end;
        }
        const auto a = run_traced(w, firmware_dir, source_dir, false), b = run_traced(w, firmware_dir, source_dir, true);
        char timeline[32];
        std::snprintf(timeline, sizeof timeline, "%s %zu", same_events(a, b) ? "same" : "DIFFER", a.size());
        const double p = median(plain_cpu), s = median(skip_cpu);
        std::printf("%-64s %7.1f %8.1fx %8.1fx %6.1fx %9s %9s\n", w.label, seconds, seconds / p, seconds / s, p / s,
                    same_end ? "yes" : "NO", timeline);
    }
    std::printf("(timeline: a traced pair of %g s each, every pin and part signal; events compared one by one)\n",
                workloads[0].traced_seconds);
}
