// The avrbench command line. Thin by design: every step here is a library
// call that tests and other tools make the same way.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
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
#include "trace/GtkwWriter.hpp"
#include "trace/Recorder.hpp"
#include "trace/VcdWriter.hpp"

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
    const double duration_s = parse_seconds(args.duration, "--for");
    Board board(std::move(spec), firmware);

    Timeline timeline;
    Recorder recorder(timeline);
    const bool tracing = !args.vcd.empty();
    if (tracing) {
        for (Mcu* m : board.mcus()) {
            if (!args.trace.empty()) recorder.trace_pins(*m, args.trace);
        }
        if (args.trace.empty()) {
            // Every MCU pin that is on a net, plus every part's signals.
            for (const auto& net : board.spec().nets) {
                for (const auto& e : net.endpoints) {
                    if (board.spec().find_mcu(e.owner) != nullptr) {
                        recorder.trace_pin(board.mcu(e.owner), board.mcu(e.owner).pin(e.pin));
                    }
                }
            }
            for (Part* p : board.parts()) recorder.trace_part(*p);
        }
    }

    ProgressBar progress(!args.quiet && isatty(STDERR_FILENO) != 0);
    const auto wall_start = std::chrono::steady_clock::now();
    const double chunk_s = std::max(duration_s / 100, 1e-6);
    while (board.now_seconds() < duration_s) {
        if (board.run_until_seconds(std::min(duration_s, board.now_seconds() + chunk_s)) == StopReason::Halted) break;
        progress.show(board.now_seconds() / duration_s, board.now_seconds());
    }
    progress.finish();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

    std::string gtkw_path;
    if (tracing) {
        VcdOptions vcd_options;
        vcd_options.end_cycle = board.mcu().cycle();
        vcd_options.end_clock_hz = board.mcu().frequency_hz();
        const VcdResult vcd = write_vcd(timeline, args.vcd, vcd_options);
        gtkw_path = with_extension(args.vcd, ".gtkw");
        GtkwOptions gtkw_options;
        gtkw_options.fit_end_time = vcd.end_time;
        gtkw_options.fit_timescale = vcd.timescale;
        write_gtkw(timeline, gtkw_path, args.vcd, gtkw_options);
    }

    const double simulated_s = board.now_seconds();
    std::printf("avrbench run: board %s (%s)\n", board.spec().name.c_str(), args.board.c_str());
    for (Mcu* m : board.mcus()) {
        std::printf("  mcu        %s: %s at %.6g MHz, firmware %s%s\n", m->name().c_str(), m->mcu_type().c_str(),
                    m->frequency_hz() / 1e6, m->elf().path().c_str(), m->halted() ? " (halted)" : "");
    }
    std::printf("  simulated  %.6f s\n", simulated_s);
    std::printf("  wall       %.3f s, real-time factor %.1fx\n", wall_s, wall_s > 0 ? simulated_s / wall_s : 0.0);
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
    const auto findings = board.findings();
    print_findings(findings);
    if (tracing) {
        std::printf("  vcd        %s (%zu signals, %zu events), gtkwave save file %s\n", args.vcd.c_str(),
                    timeline.signals().size(), timeline.events().size(), gtkw_path.c_str());
    }
    for (const auto& f : findings) {
        if (is_mcu_finding(f) || args.strict) return kExitFinding;
    }
    return kExitOk;
}

int run_command(const RunArgs& args) {
    if (!args.board.empty()) return run_board_command(args);
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
        VcdOptions vcd_options;
        vcd_options.end_cycle = mcu.cycle();
        vcd_options.end_clock_hz = mcu.frequency_hz();
        const VcdResult vcd = write_vcd(timeline, args.vcd, vcd_options);
        gtkw_path = with_extension(args.vcd, ".gtkw");
        GtkwOptions gtkw_options;
        gtkw_options.fit_end_time = vcd.end_time;
        gtkw_options.fit_timescale = vcd.timescale;
        write_gtkw(timeline, gtkw_path, args.vcd, gtkw_options);
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
    run_cmd->add_option("--for", run.duration, "simulated time to run, e.g. 2s, 250ms (default 1s)");
    run_cmd->add_flag("--until-sleep", run.until_sleep, "stop when the firmware first executes SLEEP (bounded by --for)");
    run_cmd->add_option("--uart-in", run.uart_in, "bytes to send to USART0");
    run_cmd->add_option("--uart-out", run.uart_out, "write what the firmware sent on USART0 to this file");
    run_cmd->add_flag("-q,--quiet", run.quiet, "no progress bar");

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
    } catch (const BadInput& e) {
        std::fprintf(stderr, "avrbench: error: %s\n", e.what());
        return kExitBadInput;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "avrbench: internal error: %s\n", e.what());
        return kExitInternal;
    }
    return 0;
}
