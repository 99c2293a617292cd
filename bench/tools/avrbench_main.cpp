// The avrbench command line. Thin by design: every step here is a library
// call that tests and other tools make the same way.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <vector>

#include "boards/Board.hpp"
#include "core/ElfImage.hpp"
#include "core/Errors.hpp"
#include "core/Mcu.hpp"
#include "core/Units.hpp"
#include "parts/Axis.hpp"
#include "parts/StepDirDriver.hpp"
#include "parts/ThermalPlant.hpp"
#include "trace/GtkwWriter.hpp"
#include "trace/Recorder.hpp"
#include "trace/HtmlReport.hpp"
#include "trace/VcdWriter.hpp"
#include "verify/Bench.hpp"
#include "verify/Scenario.hpp"

namespace avrbench {
namespace {

// Exit codes (docs/CLI.md).
constexpr int kExitOk = 0;
constexpr int kExitFinding = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitTimeout = 3;
constexpr int kExitInternal = 4;

struct RunArgs {
    std::string elf;
    std::string board;
    std::vector<std::string> firmware;  // mcu=path for the board's other MCUs
    bool strict = false;
    std::string mcu;
    std::string freq;
    std::string trace;
    std::string vcd;
    std::string duration = "1s";
    bool duration_given = false;
    bool until_sleep = false;
    std::string uart_in;
    std::string uart_out;
    bool quiet = false;
    std::string gcode;
    std::string host;
    std::string flow;
    bool wait_banner = false;
    std::string settle = "50ms";
    std::string report;
};

std::string read_file(const std::string& path, const char* what) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BadInput(std::string(what) + ": " + path + ": cannot open");
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

class ProgressBar {
public:
    explicit ProgressBar(bool enabled) : enabled_(enabled) {}
    void show(double fraction, double simulated_s) {
        if (!enabled_) return;
        const int width = 30;
        const int filled = static_cast<int>(fraction * width);
        std::fprintf(stderr, "\r[%.*s%*s] %3d%%  %.3f s simulated", filled, "##############################",
                     width - filled, "", static_cast<int>(fraction * 100), simulated_s);
        std::fflush(stderr);
    }
    void finish() {
        if (enabled_) std::fprintf(stderr, "\r%*s\r", 60, "");
    }

private:
    bool enabled_;
};

std::string with_extension(const std::string& path, const std::string& extension) {
    const auto slash = path.find_last_of('/');
    const auto dot = path.find_last_of('.');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) return path.substr(0, dot) + extension;
    return path + extension;
}

// Writes the VCD and, beside it, a gtkwave save file zoomed to the whole run
// (which ends at `clock`'s current cycle). Returns the save file's path.
std::string write_waveforms(const Timeline& timeline, const std::string& vcd_path, const Mcu& clock) {
    VcdOptions vcd_options;
    vcd_options.end_cycle = clock.cycle();
    vcd_options.end_clock_hz = clock.frequency_hz();
    const VcdResult vcd = write_vcd(timeline, vcd_path, vcd_options);
    const std::string gtkw_path = with_extension(vcd_path, ".gtkw");
    GtkwOptions gtkw_options;
    gtkw_options.fit_end_time = vcd.end_time;
    gtkw_options.fit_timescale = vcd.timescale;
    write_gtkw(timeline, gtkw_path, vcd_path, gtkw_options);
    return gtkw_path;
}

void print_findings(const std::vector<Finding>& findings) {
    std::printf("  findings   %zu\n", findings.size());
    for (const auto& f : findings) std::printf("    %s\n", f.describe().c_str());
}

bool is_mcu_finding(const Finding& f) { return f.has_pc; }

int run_board_command(const RunArgs& args) {
    if (!args.mcu.empty() || !args.freq.empty()) {
        throw BadInput("--mcu/--freq do not apply with --board: the board file gives each MCU's type and clock");
    }
    BoardSpec spec = load_board_file(args.board);
    std::map<std::string, std::string> firmware;
    firmware[spec.mcus.front().name] = args.elf;
    for (const auto& item : args.firmware) {
        const auto eq = item.find('=');
        if (eq == std::string::npos) throw BadInput("--firmware '" + item + "': expected MCU=ELF");
        firmware[item.substr(0, eq)] = item.substr(eq + 1);
    }
    // With a job, --for is the limit for finishing it (default 60 s).
    const double duration_s = parse_seconds(args.duration_given || args.gcode.empty() ? args.duration : "60s", "--for");
    const double settle_s = parse_seconds(args.settle, "--settle");
    Bench bench(std::move(spec), firmware);
    Board& board = bench.board();

    UartHost* host = nullptr;
    if (!args.gcode.empty()) {
        std::optional<UartHostOptions> options;
        if (!args.flow.empty() || args.wait_banner) {
            const SerialDecl* decl = args.host.empty() ? (board.spec().serial.empty() ? nullptr : &board.spec().serial.front())
                                                       : board.spec().find_serial(args.host);
            UartHostOptions o;
            if (decl != nullptr) {
                o.flow = parse_flow_control(decl->flow, decl->location);
                o.rx_buffer_bytes = decl->rx_buffer_bytes;
            }
            if (!args.flow.empty()) o.flow = parse_flow_control(args.flow, "--flow");
            if (args.wait_banner) o.startup = Startup::WaitForBanner;
            options = o;
        }
        host = &bench.host(args.host, options);
        host->load_file(args.gcode);
    }
    if (!args.vcd.empty() || !args.report.empty()) {
        if (!args.trace.empty()) {
            for (Mcu* m : board.mcus()) bench.recorder().trace_pins(*m, args.trace);
        } else {
            bench.trace_board();
        }
    }

    ProgressBar progress(!args.quiet && isatty(STDERR_FILENO) != 0);
    const auto wall_start = std::chrono::steady_clock::now();
    IdleResult outcome = IdleResult::TimeLimit;
    const double chunk_s = std::max(duration_s / 100, 1e-6);
    if (host != nullptr) {
        while (bench.now_seconds() < duration_s) {
            outcome = bench.run_until_idle(std::min(chunk_s, duration_s - bench.now_seconds()), settle_s);
            if (outcome != IdleResult::TimeLimit) break;
            progress.show(bench.now_seconds() / duration_s, bench.now_seconds());
        }
    } else {
        while (bench.now_seconds() < duration_s) {
            if (board.run_until_seconds(std::min(duration_s, bench.now_seconds() + chunk_s)) == StopReason::Halted) {
                outcome = IdleResult::Halted;
                break;
            }
            progress.show(bench.now_seconds() / duration_s, bench.now_seconds());
        }
    }
    progress.finish();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

    std::string gtkw_path;
    const Timeline& timeline = bench.timeline();
    if (!args.vcd.empty()) {
        gtkw_path = write_waveforms(timeline, args.vcd, board.mcu());
    }
    const auto findings = bench.findings();
    if (!args.report.empty()) {
        write_html_report(bench.make_report(std::string(board.mcu().elf().path()) + " on " + board.spec().name),
                          args.report);
    }

    const double simulated_s = bench.now_seconds();
    std::printf("avrbench run: board %s (%s)\n", board.spec().name.c_str(), args.board.c_str());
    for (Mcu* m : board.mcus()) {
        std::printf("  mcu        %s: %s at %.6g MHz, firmware %s%s\n", m->name().c_str(), m->mcu_type().c_str(),
                    m->frequency_hz() / 1e6, m->elf().path().c_str(), m->halted() ? " (halted)" : "");
    }
    std::printf("  simulated  %.6f s\n", simulated_s);
    std::printf("  wall       %.3f s, real-time factor %.1fx\n", wall_s, wall_s > 0 ? simulated_s / wall_s : 0.0);
    if (host != nullptr) {
        std::printf("  job        %s: %zu of %zu lines acknowledged (%zu ok, %zu error), %s\n", args.gcode.c_str(),
                    host->lines_acknowledged(), host->lines().size(), host->oks(), host->errors(), to_string(outcome));
    }
    for (Axis* axis : board.parts_of_type<Axis>()) {
        const StepDirDriver& d = axis->driver();
        if (axis->rotary()) {
            std::printf("  axis %-5s %llu steps (%llu ignored while disabled), %.3f deg, peak %.0f steps/s\n",
                        axis->name().c_str(), static_cast<unsigned long long>(d.steps_taken()),
                        static_cast<unsigned long long>(d.steps_ignored()), axis->position_deg(),
                        d.peak_step_rate_hz());
        } else {
            std::printf("  axis %-5s %llu steps (%llu ignored while disabled), at %.4f mm, peak %.0f steps/s\n",
                        axis->name().c_str(), static_cast<unsigned long long>(d.steps_taken()),
                        static_cast<unsigned long long>(d.steps_ignored()), axis->position_mm(),
                        d.peak_step_rate_hz());
        }
    }
    for (ThermalPlant* plant : board.parts_of_type<ThermalPlant>()) {
        std::printf("  thermal    %s: block %.2f degC, sensor %.2f degC, heater %.1f W now\n", plant->name().c_str(),
                    plant->block_degC(), plant->sensor_degC(), plant->heater_power_W());
    }
    print_findings(findings);
    if (host != nullptr) {
        std::printf("  transcript (last lines):\n");
        std::string tail = host->tail(10);
        std::size_t at = 0;
        while (at < tail.size()) {
            const std::size_t nl = tail.find('\n', at);
            std::printf("    %s\n", tail.substr(at, nl - at).c_str());
            at = nl == std::string::npos ? tail.size() : nl + 1;
        }
    }
    if (!args.vcd.empty()) {
        std::printf("  vcd        %s (%zu signals, %zu events), gtkwave save file %s\n", args.vcd.c_str(),
                    timeline.signals().size(), timeline.events().size(), gtkw_path.c_str());
    }
    if (!args.report.empty()) std::printf("  report     %s\n", args.report.c_str());

    for (const auto& f : findings) {
        if (is_mcu_finding(f) || (args.strict && f.kind != FindingKind::HostProtocol)) return kExitFinding;
    }
    if (host != nullptr && outcome == IdleResult::HostFailed) {
        std::fprintf(stderr, "avrbench: %s\n", host->failure_message().c_str());
        // A host that got no answer is a timeout; error/ALARM/!! are findings.
        bool timed_out = false;
        for (const auto& e : host->events()) {
            timed_out = timed_out || e.kind == HostEventKind::Timeout || e.kind == HostEventKind::BannerTimeout;
        }
        return timed_out ? kExitTimeout : kExitFinding;
    }
    if (host != nullptr && outcome == IdleResult::TimeLimit) {
        std::fprintf(stderr, "avrbench: timeout: the job was not finished within %g s (%zu of %zu lines acknowledged)\n",
                     duration_s, host->lines_acknowledged(), host->lines().size());
        return kExitTimeout;
    }
    if (args.strict) {
        for (const auto& f : findings) {
            if (f.kind == FindingKind::HostProtocol) return kExitFinding;
        }
    }
    return kExitOk;
}

int run_command(const RunArgs& args) {
    if (!args.board.empty()) return run_board_command(args);
    if (!args.gcode.empty()) throw BadInput("--gcode needs --board (the board file names the serial port)");
    if (!args.report.empty()) throw BadInput("--report needs --board");
    const ElfImage elf = ElfImage::load(args.elf);
    McuOptions options;
    options.name = "mcu";
    options.mcu_type = args.mcu;
    if (!args.freq.empty()) options.frequency_hz = parse_frequency_hz(args.freq, "--freq");
    const double duration_s = parse_seconds(args.duration, "--for");
    std::string uart_in_bytes;
    if (!args.uart_in.empty()) uart_in_bytes = read_file(args.uart_in, "--uart-in");

    Mcu mcu(elf, options);
    Timeline timeline;
    Recorder recorder(timeline);
    const bool tracing = !args.vcd.empty() || !args.trace.empty();
    if (tracing) recorder.trace_pins(mcu, args.trace.empty() ? "all" : args.trace);

    Uart* uart0 = nullptr;
    try {
        uart0 = &mcu.uart(0);
    } catch (const BadInput&) {
        if (!args.uart_in.empty() || !args.uart_out.empty()) throw;
    }
    if (uart0 != nullptr && tracing) recorder.trace_uart_tx(mcu, *uart0);
    if (!uart_in_bytes.empty()) uart0->send(uart_in_bytes);

    const Cycle end_cycle = mcu.cycles_from_seconds(duration_s);
    ProgressBar progress(!args.quiet && isatty(STDERR_FILENO) != 0);
    const auto wall_start = std::chrono::steady_clock::now();
    bool slept = false;
    if (args.until_sleep) {
        while (mcu.cycle() < end_cycle && !mcu.sleeping() && mcu.step()) {
        }
        slept = mcu.sleeping();
    } else {
        const Cycle chunk = std::max<Cycle>(end_cycle / 100, 1);
        while (mcu.cycle() < end_cycle) {
            if (mcu.run_until(std::min(end_cycle, mcu.cycle() + chunk)) == StopReason::Halted) break;
            progress.show(static_cast<double>(mcu.cycle()) / static_cast<double>(end_cycle), mcu.seconds());
        }
    }
    progress.finish();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

    if (!args.uart_out.empty()) {
        std::ofstream out(args.uart_out, std::ios::binary);
        if (!out) throw BadInput("--uart-out: " + args.uart_out + ": cannot write");
        const std::string text = uart0->transmitted_text();
        out.write(text.data(), static_cast<std::streamsize>(text.size()));
    }
    std::string gtkw_path;
    if (!args.vcd.empty()) {
        gtkw_path = write_waveforms(timeline, args.vcd, mcu);
    }

    const double simulated_s = mcu.seconds();
    std::printf("avrbench run: %s on %s at %.6g MHz\n", args.elf.c_str(), mcu.mcu_type().c_str(),
                mcu.frequency_hz() / 1e6);
    std::printf("  simulated  %.6f s (%llu cycles)\n", simulated_s, static_cast<unsigned long long>(mcu.cycle()));
    std::printf("  wall       %.3f s, real-time factor %.1fx\n", wall_s, wall_s > 0 ? simulated_s / wall_s : 0.0);
    if (args.until_sleep) std::printf("  stopped    %s\n", slept ? "firmware executed SLEEP" : "time limit");
    if (mcu.halted()) std::printf("  halted     %s\n", mcu.halt_reason().c_str());
    if (uart0 != nullptr) {
        std::printf("  uart0      %zu bytes from firmware, %llu bytes to firmware\n", uart0->transmitted().size(),
                    static_cast<unsigned long long>(uart0->bytes_delivered()));
    }
    print_findings(mcu.findings());
    if (!args.vcd.empty()) {
        std::printf("  vcd        %s (%zu signals, %zu events), gtkwave save file %s\n", args.vcd.c_str(),
                    timeline.signals().size(), timeline.events().size(), gtkw_path.c_str());
    }
    if (!mcu.findings().empty()) return kExitFinding;
    if (args.until_sleep && !slept && !mcu.halted()) {
        std::fprintf(stderr, "avrbench: timeout: the firmware did not execute SLEEP within %s\n", args.duration.c_str());
        return kExitTimeout;
    }
    return kExitOk;
}

// build/avrbench -> build/firmware, where the build puts our firmware ELFs.
std::string default_firmware_dir() {
    if (const char* env = std::getenv("AVRBENCH_FIRMWARE_DIR")) return env;
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::string("build/firmware") : (exe.parent_path() / "firmware").string();
}

struct CheckArgs {
    std::vector<std::string> scenarios;
    std::string junit;
    std::string report_dir;
    std::string firmware_dir;
};

// GoogleTest's sharding variables, so a CI matrix splits scenario lists the
// way it splits gtest binaries.
std::vector<std::string> shard(const std::vector<std::string>& all) {
    const char* total_env = std::getenv("GTEST_TOTAL_SHARDS");
    const char* index_env = std::getenv("GTEST_SHARD_INDEX");
    if (total_env == nullptr || index_env == nullptr) return all;
    const long total = std::strtol(total_env, nullptr, 10), index = std::strtol(index_env, nullptr, 10);
    if (total <= 0 || index < 0 || index >= total) throw BadInput("GTEST_TOTAL_SHARDS/GTEST_SHARD_INDEX are inconsistent");
    std::vector<std::string> mine;
    for (std::size_t i = 0; i < all.size(); ++i) {
        if (static_cast<long>(i % static_cast<std::size_t>(total)) == index) mine.push_back(all[i]);
    }
    return mine;
}

int check_command(const CheckArgs& args, bool update_golden) {
    const std::string firmware_dir = args.firmware_dir.empty() ? default_firmware_dir() : args.firmware_dir;
    std::vector<ScenarioSpec> specs;
    for (const auto& path : update_golden ? args.scenarios : shard(args.scenarios)) specs.push_back(load_scenario(path, firmware_dir));
    std::vector<ScenarioResult> results;
    ScenarioRunOptions options;
    options.report_dir = args.report_dir;
    options.update_golden = update_golden;
    for (const auto& spec : specs) {
        results.push_back(run_scenario(spec, options));
        const auto& r = results.back();
        if (update_golden) {
            std::printf("%s: golden timeline written to %s (%.3f s simulated)\n", spec.name.c_str(),
                        spec.golden_path.empty() ? "(none: the scenario names no golden)" : spec.golden_path.c_str(),
                        r.simulated_s);
            for (const auto& f : r.failures) std::printf("  note: %s\n", f.c_str());
        } else {
            std::fputs(r.text().c_str(), stdout);
        }
    }
    if (!args.junit.empty()) {
        std::ofstream out(args.junit, std::ios::binary);
        if (!out) throw BadInput("--junit: " + args.junit + ": cannot write");
        out << junit_xml(results, "avrbench");
    }
    if (update_golden) return kExitOk;
    std::size_t failed = 0;
    for (const auto& r : results) failed += r.passed ? 0 : 1;
    std::printf("%zu passed, %zu failed\n", results.size() - failed, failed);
    return failed == 0 ? kExitOk : kExitFinding;
}

}  // namespace
}  // namespace avrbench

int main(int argc, char** argv) {
    using namespace avrbench;
    CLI::App app{"avrbench: a cycle-level test bench for AVR firmware (simavr inside)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("avrbench ") + AVRBENCH_VERSION);

    RunArgs run;
    CLI::App* run_cmd = app.add_subcommand("run", "run a firmware ELF and record its pins");
    run_cmd->add_option("elf", run.elf, "firmware ELF (the file you would flash)")->required();
    run_cmd->add_option("--board", run.board, "board file (bench/boards/*.yaml): MCUs, parts, nets; ELF runs on its first MCU");
    run_cmd->add_option("--firmware", run.firmware, "MCU=ELF for a board's other MCUs (repeatable)");
    run_cmd->add_flag("--strict", run.strict, "part findings (driver timing, axis crashes) also give exit code 1");
    run_cmd->add_option("--mcu", run.mcu, "MCU type, e.g. atmega328p (default: from the ELF's .mmcu section)");
    run_cmd->add_option("--freq", run.freq, "clock, e.g. 16MHz (default: from the ELF's .mmcu section)");
    run_cmd->add_option("--trace", run.trace, "pins to record: PB5,PD2 | PORTB | all (default with --vcd: all)");
    run_cmd->add_option("--vcd", run.vcd, "write the recorded signals as VCD (+ a .gtkw save file beside it)");
    run_cmd->add_option("--for", run.duration, "simulated time to run, e.g. 2s, 250ms (default 1s; with --gcode the limit for the job, default 60s)")
        ->each([&run](const std::string&) { run.duration_given = true; });
    run_cmd->add_option("--gcode", run.gcode, "stream this G-code file to the board's serial port (needs --board)");
    run_cmd->add_option("--host", run.host, "the board's serial port for --gcode (default: the first)");
    run_cmd->add_option("--flow", run.flow, "send_and_wait | character_counting (default: the board's)");
    run_cmd->add_flag("--wait-banner", run.wait_banner, "send the job only after the firmware's first output line");
    run_cmd->add_option("--settle", run.settle, "motion has stopped after no STEP edge for this long (default 50ms)");
    run_cmd->add_option("--report", run.report, "write an HTML report of the run (with --board)");
    run_cmd->add_flag("--until-sleep", run.until_sleep, "stop when the firmware first executes SLEEP (bounded by --for)");
    run_cmd->add_option("--uart-in", run.uart_in, "bytes to send to USART0");
    run_cmd->add_option("--uart-out", run.uart_out, "write what the firmware sent on USART0 to this file");
    run_cmd->add_flag("-q,--quiet", run.quiet, "no progress bar");

    CheckArgs check;
    CLI::App* check_cmd = app.add_subcommand("check", "run scenario files: stimulus, expectations, golden comparison");
    check_cmd->add_option("scenarios", check.scenarios, "scenario files (tests/scenarios/*.yaml)")->required();
    check_cmd->add_option("--junit", check.junit, "write JUnit XML for CI");
    check_cmd->add_option("--report-dir", check.report_dir, "write an HTML report per scenario here");
    check_cmd->add_option("--firmware-dir", check.firmware_dir, "where bare firmware names resolve (default: beside avrbench)");
    CheckArgs golden;
    CLI::App* golden_cmd = app.add_subcommand("golden", "manage golden timelines");
    golden_cmd->require_subcommand(1);
    CLI::App* update_cmd = golden_cmd->add_subcommand("update", "rerun scenarios and rewrite their golden timelines (never done implicitly)");
    update_cmd->add_option("scenarios", golden.scenarios, "scenario files")->required();
    update_cmd->add_option("--firmware-dir", golden.firmware_dir, "where bare firmware names resolve");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "avrbench: usage error: %s (see avrbench --help)\n", e.what());
        return kExitBadInput;
    }
    try {
        if (run_cmd->parsed()) return run_command(run);
        if (check_cmd->parsed()) return check_command(check, false);
        if (update_cmd->parsed()) return check_command(golden, true);
    } catch (const BadInput& e) {
        std::fprintf(stderr, "avrbench: error: %s\n", e.what());
        return kExitBadInput;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "avrbench: internal error: %s\n", e.what());
        return kExitInternal;
    }
    return 0;
}
