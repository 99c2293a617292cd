#include "FirmwareTarget.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <simavr/avr_eeprom.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_interrupts.h>
#include <simavr/sim_irq.h>

#include "SnapshotHeap.hpp"
#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"
#include "parts/Part.hpp"
#include "run/Bench.hpp"

namespace avrbench::fuzz {

namespace {

// Never destroyed: at exit the fixes' registries (function-local statics)
// may go first, and the process is ending anyway.
Bench* g_bench = nullptr;
// The board's parts, listed once at boot: an input allocates nothing for
// them (a restore copies back every page an input wrote).
std::vector<Part*> g_parts;
TargetConfig g_config;
std::string g_mcu_name;  // the fuzzed MCU: the serial port's
std::size_t g_findings_at_ready = 0;
// Per source (MCU, part, net): how many findings it had at ready. Board::
// findings() groups them by source, so a new one of an early source comes
// before an old one of a later source.
std::map<std::string, std::size_t> g_findings_at_ready_by_source;

std::string env_or_die(const char* name, const char* who) {
    const char* value = std::getenv(name);
    if (value == nullptr || *value == '\0') {
        std::fprintf(stderr, "%s: set %s (see bench/fuzz/FirmwareTarget.hpp)\n", who, name);
        std::exit(2);
    }
    return value;
}

// A restart mid-job is not one: grbl's ^X restarts on purpose, and a reset
// the firmware did not ask for is already an MCU finding (watchdog, jump to 0).
bool is_oracle_event(HostEventKind kind) { return kind == HostEventKind::Timeout || kind == HostEventKind::Fatal; }

// NAME=VALUE lines of `<executable>.avrbench` into the environment (never
// over a variable already set), "$ORIGIN" standing for the executable's directory.
void load_config_file(const char* executable, const char* who) {
    if (executable == nullptr || std::getenv("AVRBENCH_FUZZ_BOARD") != nullptr) return;
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::canonical(executable, ec);
    if (ec) return;
    const std::string path = exe.string() + ".avrbench";
    std::ifstream in(path);
    if (!in) return;
    const std::string origin = exe.parent_path().string();
    int line_number = 0;
    for (std::string line; std::getline(in, line);) {
        ++line_number;
        if (line.empty() || line[0] == '#') continue;
        const auto equals = line.find('=');
        if (equals == std::string::npos || equals == 0) {
            std::fprintf(stderr, "%s: %s:%d: expected NAME=VALUE\n", who, path.c_str(), line_number);
            std::exit(2);
        }
        std::string value = line.substr(equals + 1);
        for (std::size_t at; (at = value.find("$ORIGIN")) != std::string::npos;) value.replace(at, 7, origin);
        ::setenv(line.substr(0, equals).c_str(), value.c_str(), 0);
    }
}

}  // namespace

TargetConfig config_from_environment(const char* who, const char* executable) {
    load_config_file(executable, who);
    TargetConfig config;
    config.board = env_or_die("AVRBENCH_FUZZ_BOARD", who);
    config.elf = env_or_die("AVRBENCH_FUZZ_ELF", who);
    if (const char* family = std::getenv("AVRBENCH_FUZZ_FAMILY")) config.family = family;
    if (const char* bound = std::getenv("AVRBENCH_FUZZ_BOUND")) config.bound_s = std::max(0.01, std::atof(bound));
    if (const char* settle = std::getenv("AVRBENCH_FUZZ_SETTLE")) config.settle_s = std::max(0.0, std::atof(settle));
    if (const char* raw = std::getenv("AVRBENCH_FUZZ_RAW")) config.raw = std::string(raw) == "1";
    if (const char* hang = std::getenv("AVRBENCH_FUZZ_HANG")) config.hang_at_bound = std::string(hang) == "1";
    if (const char* boot = std::getenv("AVRBENCH_FUZZ_BOOT")) config.boot_s = std::max(0.0, std::atof(boot));
    if (const char* steady = std::getenv("AVRBENCH_FUZZ_STEADY")) {
        char* end = nullptr;
        const unsigned long long value = std::strtoull(steady, &end, 10);
        if (end == steady || *end != '\0') {
            std::fprintf(stderr, "%s: AVRBENCH_FUZZ_STEADY: '%s' is not a count of instructions\n", who, steady);
            std::exit(2);
        }
        config.steady_instructions = value;
    }
    if (const char* fork = std::getenv("AVRBENCH_FUZZ_FORK")) config.fork = std::string(fork) == "1";
    if (!snapshot_heap::available()) config.fork = true;
    if (const char* list = std::getenv("AVRBENCH_FUZZ_FIRMWARE")) {
        std::string entries = list;
        for (std::size_t start = 0; start < entries.size();) {
            std::size_t end = entries.find(';', start);
            if (end == std::string::npos) end = entries.size();
            const std::string entry = entries.substr(start, end - start);
            const auto equals = entry.find('=');
            if (equals == std::string::npos || equals == 0 || equals + 1 == entry.size()) {
                std::fprintf(stderr, "%s: AVRBENCH_FUZZ_FIRMWARE: '%s' is not mcu=elf\n", who, entry.c_str());
                std::exit(2);
            }
            config.other_firmware[entry.substr(0, equals)] = entry.substr(equals + 1);
            start = end + 1;
        }
    }
    return config;
}

bool target_is_raw() { return g_config.raw; }

namespace {
void boot(const TargetConfig& config, const char* who);
}

bool target_restores() { return !g_config.fork; }

void boot_target(const TargetConfig& config, const char* who) {
    g_config = config;
    {
        // Everything the board allocates from here on is in the snapshot.
        std::optional<snapshot_heap::Collecting> collecting;
        if (!config.fork) collecting.emplace();
        boot(config, who);
    }
    if (!config.fork) snapshot_heap::take();
}

namespace {

void boot(const TargetConfig& config, const char* who) {
    try {
        BoardSpec spec = load_board_file(config.board);
        g_mcu_name = spec.serial_port_mcu();
        if (g_mcu_name.empty()) {
            std::fprintf(stderr, "%s: %s has no serial port (a serial_host part) to send the input to\n", who,
                         config.board.c_str());
            std::exit(2);
        }
        std::map<std::string, std::string> firmware = config.other_firmware;
        firmware[g_mcu_name] = config.elf;
        g_bench = new Bench(std::move(spec), firmware);
        Mcu& mcu = g_bench->mcu(g_mcu_name);
        if (config.raw) {
            (void)g_bench->serial();  // the USART model listens from here on
            g_bench->run_for(config.boot_s);
        } else {
            UartHostOptions options = default_host_options(g_bench->serial_port());
            if (!config.family.empty()) options.family = parse_firmware_family(config.family, "AVRBENCH_FUZZ_FAMILY");
            // A generic firmware has no welcome the host knows: it would get
            // every input at reset and pay for the whole boot in each
            // (grbl_stepper: 50 ms writing its EEPROM defaults, a busy wait
            // on EEPE). Its first output line instead, at most boot_s.
            start_generic_after_boot(options, config.boot_s);
            UartHost& host = g_bench->host("", options);
            const Cycle limit = mcu.cycle() + mcu.cycles_from_seconds(host.options().banner_timeout_s + 0.5);
            while (!host.ready() && !host.failed() && !mcu.halted() && mcu.cycle() < limit) g_bench->run_for(0.001);
            if (!host.ready()) {
                std::fprintf(stderr, "%s: %s never became ready on %s (%s)\n", who, config.elf.c_str(),
                             config.board.c_str(), host.failed() ? host.failure_message().c_str() : "no banner");
                std::exit(2);
            }
        }
        g_parts = g_bench->board().parts();
        const auto at_ready = g_bench->board().findings();
        g_findings_at_ready = at_ready.size();
        for (const auto& f : at_ready) ++g_findings_at_ready_by_source[f.source];
    } catch (const BadInput& e) {
        std::fprintf(stderr, "%s: %s\n", who, e.what());
        std::exit(2);
    }
}

}  // namespace

void run_input(const std::uint8_t* data, std::size_t size, std::uint8_t* edge_map, std::uint32_t edge_mask,
               InputOutcome& outcome) {
    Bench& bench = *g_bench;
    Mcu& mcu = bench.mcu(g_mcu_name);
    UartHost* host = g_config.raw ? nullptr : &bench.host();
    SerialLink& serial = bench.serial();
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    if (host != nullptr) {
        try {
            host->add_lines(bytes);
        } catch (const BadInput&) {
            return;  // nothing the host would send (it refuses such a job up front)
        }
    } else {
        serial.send(bytes);
    }
    // Done sending: every line answered (or the host gave up), or every raw byte taken.
    const auto sent = [&] { return host != nullptr ? host->finished() : serial.pending_rx() == 0; };
    const Cycle start = mcu.cycle();
    Cycle end = start + mcu.cycles_from_seconds(g_config.bound_s);
    // The board's run loop with the fuzzed MCU covering (Mcu::set_run_coverage:
    // alone, or in the lockstep among the board's other MCUs), in slices of
    // 1 ms simulated between which the settle time may start.
    PcEdgeMap edges{edge_map, edge_mask};
    mcu.set_run_coverage(&edges);
    const Cycle slice = mcu.cycles_from_seconds(0.001);
    const std::uint64_t steps_before = mcu.steps();
    bool settling = false;
    // The first finding ends the input: only it is reported, and an input
    // that drives a carriage into its end would otherwise run to the bound.
    const auto found = [&] {
        if (bench.board().finding_count() > g_findings_at_ready) return true;
        if (host == nullptr) return false;
        for (const auto& e : host->events()) {
            if (is_oracle_event(e.kind)) return true;
        }
        return false;
    };
    // Until the firmware is done as a run's job is (Bench::still_going: every
    // line answered, every accepted move made, heaters at their targets, no
    // step for settle_s), the first finding, or the bound.
    const Picoseconds settle_ps = ps_from_seconds(g_config.settle_s, "AVRBENCH_FUZZ_SETTLE");
    // Repeating itself: since the last new coverage feature, `steady`
    // instructions ran, the machine stepped in the last slice, and no part
    // could find more going on at that pace until the bound. The rest of the
    // bound would most likely run the window again (a change of behaviour
    // after a longer quiet stretch is not followed: docs/FUZZING.md); it is
    // the long moves' cost (grbl_stepper: a 3 s move is 24 000 step interrupts).
    std::uint64_t features_seen = edges.features;
    std::uint64_t steady_from = mcu.steps();
    const auto mark_pace = [&] {
        for (Part* part : g_parts) part->mark_pace();
    };
    mark_pace();
    const auto repeating = [&](double slice_start_s) {
        if (g_config.steady_instructions == 0) return false;
        if (edges.features != features_seen) {
            features_seen = edges.features;
            steady_from = mcu.steps();
            mark_pace();
            return false;
        }
        if (mcu.steps() - steady_from < g_config.steady_instructions) return false;
        if (bench.last_step_seconds() < slice_start_s) return false;  // not stepping: the hang oracles' time
        const double left_s = static_cast<double>(end - mcu.cycle()) / static_cast<double>(mcu.frequency_hz());
        for (Part* part : g_parts) {
            if (part->may_find_more_at_pace(left_s)) return false;
        }
        return true;
    };
    while (mcu.cycle() < end && !mcu.halted() && !found()) {
        if (!settling && sent()) settling = true;
        // At least one slice: an input with nothing to send (an empty line)
        // still runs the firmware, whose edges AFL++ needs to see some of.
        if (settling && mcu.cycle() != start && !bench.still_going(settle_ps)) break;
        const Cycle from = mcu.cycle();
        const Cycle to = std::min(end, from + slice);
        const double from_s = bench.now_seconds();
        bench.run_for(static_cast<double>(to - from) / mcu.frequency_hz());
        bench.sample_heaters();
        if (!found() && repeating(from_s)) {
            outcome.ended_steady = true;
            break;
        }
        if (mcu.cycle() == from) break;  // nothing moved (a stop): never spin
    }
    mcu.set_run_coverage(nullptr);
    outcome.steps = mcu.steps() - steps_before;
    std::string detail;
    // The MCU's, the nets', the parts' (grouped by source): the earliest new one.
    const auto findings = bench.board().findings();
    const Finding* first = nullptr;
    const auto seconds = [](const Finding& f) { return f.clock_hz != 0 ? static_cast<double>(f.cycle) / f.clock_hz : 0.0; };
    std::map<std::string, std::size_t> seen_by_source;
    for (const Finding& f : findings) {
        const auto old = g_findings_at_ready_by_source.find(f.source);
        if (++seen_by_source[f.source] <= (old != g_findings_at_ready_by_source.end() ? old->second : 0)) continue;
        if (first == nullptr || seconds(f) < seconds(*first)) first = &f;
    }
    if (first != nullptr) detail = first->describe();
    if (detail.empty() && host != nullptr) {
        for (const auto& e : host->events()) {
            if (is_oracle_event(e.kind)) {
                detail = std::string(to_string(e.kind)) + ": " + e.message;
                break;
            }
        }
    }
    // Not a hang: a machine that stepped within the line timeout is at work
    // on the line (an input that asks for more than the bound's time).
    const bool stepping = bench.last_step_seconds() >= 0 && host != nullptr &&
                          bench.now_seconds() - bench.last_step_seconds() < host->line_timeout_s();
    if (detail.empty() && host != nullptr && g_config.hang_at_bound && !outcome.ended_steady && !settling &&
        !mcu.halted() && !stepping &&
        host->outstanding_lines() > 0 && host->lines_acknowledged() < host->lines().size()) {
        // The oldest line still waiting when the input's simulated time ran out.
        const GcodeLine& line = host->lines()[host->lines_acknowledged()];
        char bound[32];
        std::snprintf(bound, sizeof bound, "%g", g_config.bound_s);
        detail = "hang: line " + std::to_string(line.number) + " " + quoted_line(line.text) +
                 " got no answer within the bound of " + bound + " s (keep-alives not counted)";
    }
    if (!detail.empty()) {
        outcome.finding = true;
        std::snprintf(outcome.detail, sizeof outcome.detail, "%s", detail.c_str());
    }
}

void run_input_and_restore(const std::uint8_t* data, std::size_t size, std::uint8_t* edges, std::uint32_t edge_mask,
                           InputOutcome& outcome) {
    // The first input runs on the process's heap (SnapshotHeap.hpp): what it
    // makes lazily for the whole process (stdio buffers; function-local
    // statics are on the process heap anyway) then outlives the restores.
    // Where its allocations live changes nothing of what it does.
    static bool first_input_done = false;
    if (!first_input_done) {
        first_input_done = true;
        run_input(data, size, edges, edge_mask, outcome);
    } else {
        const snapshot_heap::Collecting collecting;
        run_input(data, size, edges, edge_mask, outcome);
    }
    snapshot_heap::restore();
}

namespace {

// One line per item: "name value", the value a hash where it is long.
class StateLines {
public:
    void add(const std::string& name, const std::string& value) { out_ << name << ' ' << value << '\n'; }
    void add(const std::string& name, std::uint64_t value) { out_ << name << ' ' << value << '\n'; }
    void add_bytes(const std::string& name, const std::uint8_t* bytes, std::size_t size) {
        std::uint64_t hash = 0xcbf29ce484222325ull;  // FNV-1a
        for (std::size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 0x100000001b3ull;
        char text[40];
        std::snprintf(text, sizeof text, "%zu:%016llx", size, static_cast<unsigned long long>(hash));
        add(name, text);
    }
    std::string str() const { return out_.str(); }

private:
    std::ostringstream out_;
};

void add_mcu_state(StateLines& lines, const std::string& name, Mcu& mcu) {
    avr_t* avr = mcu.avr();
    const std::string p = name + ".";
    lines.add(p + "cycle", avr->cycle);
    lines.add(p + "pc", avr->pc);
    lines.add(p + "state", static_cast<std::uint64_t>(avr->state));
    lines.add(p + "steps", mcu.steps());
    lines.add_bytes(p + "sreg", avr->sreg, sizeof avr->sreg);
    lines.add_bytes(p + "data", avr->data, static_cast<std::size_t>(avr->ramend) + 1);  // registers, I/O, SRAM
    lines.add_bytes(p + "flash", avr->flash, static_cast<std::size_t>(avr->flashend) + 1);
    // simavr 1.6's EEPROM_GET answers -1 even when it filled the
    // descriptor: the pointer says whether it did.
    avr_eeprom_desc_t eeprom{};
    eeprom.size = avr->e2end + 1;
    (void)avr_ioctl(avr, AVR_IOCTL_EEPROM_GET, &eeprom);
    if (eeprom.ee != nullptr) lines.add_bytes(p + "eeprom", eeprom.ee, eeprom.size);
    std::string irqs;
    for (int i = 0; i < avr->irq_pool.count; ++i) {
        const avr_irq_t* irq = avr->irq_pool.irq[i];
        irqs += std::to_string(irq->value) + (irq->flags & IRQ_FLAG_INIT ? "i" : "") + ",";
    }
    lines.add_bytes(p + "irq_values", reinterpret_cast<const std::uint8_t*>(irqs.data()), irqs.size());
    std::string pending;
    for (int i = 0; i < avr->interrupts.vector_count; ++i) {
        const avr_int_vector_t* v = avr->interrupts.vector[i];
        pending += std::to_string(v->vector) + (v->pending ? "p" : "") + ",";
    }
    pending += "running=" + std::to_string(avr->interrupts.running_ptr);
    lines.add(p + "interrupts", pending);
    // Pending cycle timers: when each falls due, from now (the callbacks are
    // the same code at the same addresses).
    std::string timers;
    for (const avr_cycle_timer_slot_t* t = avr->cycle_timers.timer; t != nullptr; t = t->next) {
        timers += std::to_string(t->when - avr->cycle) + ",";
    }
    lines.add(p + "cycle_timers", timers);
}

}  // namespace

std::string observable_state() {
    Bench& bench = *g_bench;
    StateLines lines;
    for (Mcu* mcu : bench.board().mcus()) add_mcu_state(lines, mcu->name(), *mcu);
    for (const auto& net : bench.board().nets()) lines.add("net." + net->name(), net->level() ? 1 : 0);
    for (Part* part : bench.board().parts()) lines.add("part." + std::string(part->name()), part->summary());
    if (!g_config.raw) {
        UartHost& host = bench.host();
        lines.add("host.lines", host.lines().size());
        lines.add("host.acknowledged", host.lines_acknowledged());
        lines.add("host.events", host.events().size());
        lines.add("host.ready", host.ready() ? 1 : 0);
    }
    lines.add("serial.pending_rx", bench.serial().pending_rx());
    std::string findings;
    for (const Finding& f : bench.board().findings()) findings += f.describe() + "\n";
    lines.add_bytes("findings", reinterpret_cast<const std::uint8_t*>(findings.data()), findings.size());
    return lines.str();
}

}  // namespace avrbench::fuzz
