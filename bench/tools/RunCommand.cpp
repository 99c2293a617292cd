// `avrbench run`: a firmware on a board (run/BoardRun) or on a bare MCU.
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>

#include "cam/PlotJob.hpp"
#include "mcu/ElfImage.hpp"
#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "mcu/Mcu.hpp"
#include "core/OutputFile.hpp"
#include "mcu/TimingProfile.hpp"
#include "core/Units.hpp"
#include "core/UserStop.hpp"
#include "debug/DebugRun.hpp"
#include "debug/Debugger.hpp"
#include "debug/RunViews.hpp"
#include "tools/Commands.hpp"
#include "tools/FirmwareArgs.hpp"
#include "tools/RealtimeArgs.hpp"
#include "trace/Recorder.hpp"
#include "trace/WaveformFiles.hpp"
#include "run/McuRun.hpp"

namespace avrbench {
namespace {

struct RunArgs {
    std::string elf;
    std::string board;
    std::vector<std::string> firmware;  // mcu=path for the board's other MCUs
    bool strict = false;
    std::string mcu;
    std::string freq;
    std::string trace;       // pins added to what a run records by default
    std::string trace_only;  // pins recorded instead of the defaults
    std::string vcd;
    std::string vcd_format = "portable";
    std::string duration = "1s";
    bool duration_given = false;
    bool until_sleep = false;
    std::vector<std::string> uart_in;   // FILE, or PORT=FILE on a board
    std::vector<std::string> uart_out;  // FILE, or PORT=FILE on a board
    bool quiet = false;
    std::string dxf;            // seed 002: a drawing to plot through the CAM and binary records
    std::string records = "faithful";
    std::string feed = "120";   // mm/min, for --dxf
    std::string nc;             // --dxf: also write the G-code here
    std::string pty;            // a serial port bridged to a pseudo-terminal
    std::string pty_link;       // and a stable symlink to it
    std::string pace = "free";  // free | realtime
    bool reset_on_open = false; // --pty: a host opening the port resets its MCU
    std::string status_every;   // a status line every this much simulated time
    std::string status_file;    // and the JSON status rewritten there
    std::string gcode;
    bool gcode_bytes = false;  // --gcode-bytes: no text check (fuzzing reproducers)
    std::string host;
    std::string flow;
    bool wait_banner = false;
    std::string generic_boot;  // "" = none
    std::string settle = "50ms";
    std::string report;
    std::string profile;  // --profile: the timing profile as JSON
    std::string family;        // --family: overrides the board's
    std::vector<std::string> error_patterns;  // --error-pattern: besides the family's error lines
    std::string line_timeout;  // --line-timeout: overrides the board's
    std::vector<std::string> realtime;  // --realtime TIME=BYTES (repeatable)
    bool no_idle_skip = false;          // --no-idle-skip: run every pass of idle loops
    bool simavr_core = false;           // --simavr-core: execute on avr_run_one, not the predecoded core
    bool no_block_translation = false;  // --no-block-translation: the predecoded core interprets every instruction
    bool no_periodic_waves = false;     // --no-periodic-waves: every PWM edge through the nets
    std::vector<std::string> gdb;       // --gdb [MCU=]PORT (repeatable)
    bool break_at_finding = false;
    std::string break_at;               // --break-at TIME
    std::string break_at_cycle;         // --break-at-cycle N
};

// --gdb and the --break-at options as the debugger's options; nullopt without --gdb.
std::optional<DebugOptions> debug_options(const RunArgs& args) {
    if (!args.gdb.empty() && !args.pty.empty() && args.pace == "realtime") {
        throw BadInput("--gdb with --pace realtime: a stopped MCU would hold wall time back; debug at --pace free");
    }
    return debug_options(DebugArgs{args.gdb, args.break_at_finding, args.break_at, args.break_at_cycle});
}


// "FILE" (the board's first serial port, or USART0 without a board) or "PORT=FILE".
struct PortFile {
    std::string port;  // "" = the first
    std::string path;
};

std::vector<PortFile> port_files(const std::vector<std::string>& items, const char* option) {
    std::vector<PortFile> out;
    for (const auto& item : items) {
        const auto eq = item.find('=');
        PortFile pf = eq == std::string::npos ? PortFile{"", item} : PortFile{item.substr(0, eq), item.substr(eq + 1)};
        if (pf.path.empty()) throw BadInput(std::string(option) + " '" + item + "': no file name");
        for (const auto& other : out) {
            if (other.port == pf.port) {
                throw BadInput(std::string(option) + ": port " + (pf.port.empty() ? "(default)" : pf.port) + " given twice");
            }
        }
        out.push_back(pf);
    }
    return out;
}

// --uart-in's bytes: a regular file, or "-" for standard input (a pipe on
// purpose, read to its end), both at most kMaxUartInputBytes.
std::string read_uart_input(const std::string& path) {
    if (path != "-") return read_input_file(path, "--uart-in", kMaxUartInputBytes);
    std::string bytes;
    char buffer[65536];
    for (;;) {
        const ssize_t n = ::read(STDIN_FILENO, buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw BadInput(std::string("--uart-in -: cannot read standard input: ") + std::strerror(errno));
        if (n == 0) return bytes;
        bytes.append(buffer, static_cast<std::size_t>(n));
        if (bytes.size() > kMaxUartInputBytes) {
            throw BadInput("--uart-in -: standard input holds more than " + std::to_string(kMaxUartInputBytes >> 20) +
                           " MiB (docs/CLI.md, \"Limits\")");
        }
    }
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


// --vcd-format: portable (every reader, sigrok included) or compact (gtkwave's vectors and shared codes).
VcdOptions vcd_layout(const RunArgs& args) {
    VcdOptions layout;
    if (args.vcd_format == "compact") {
        layout.buses = VcdBuses::Vector;
        layout.alias_codes = false;
    }
    return layout;
}

// --dxf: the drawing through seed 002's CAM to binary records (docs/CNC.md).
BoardRunOptions::RecordJob plot_job(const RunArgs& args) {
    if (args.records != "faithful" && args.records != "improved") {
        throw BadInput("--records: '" + args.records + "' is not faithful or improved");
    }
    const double feed = parse_quantity(args.feed, Dimension::Dimensionless, "--feed");
    PlotJob plot = plot_drawing(args.dxf, feed, args.records == "improved");
    if (!args.nc.empty()) write_output_file(args.nc, plot.gcode, "--nc");
    return {args.dxf, args.records, std::move(plot.records.messages), std::move(plot.records.busy_seconds), std::move(plot.gcode)};
}

// `run --board`'s arguments as the library's run options, checked as far as
// they can be without the board.
BoardRunOptions board_run_options(const RunArgs& args, ProgressBar& progress) {
    if (!args.mcu.empty() || !args.freq.empty()) {
        throw BadInput("--mcu/--freq do not apply with --board: the board file gives each MCU's type and clock");
    }
    BoardRunOptions o;
    o.board = args.board;
    o.elf = args.elf;
    o.firmware = firmware_assignments(args.firmware);
    // With a job, --for is the limit for finishing it (default 60 s; a plot 600 s).
    const char* job_default = !args.dxf.empty() ? "600s" : "60s";
    const bool job = !args.gcode.empty() || !args.dxf.empty();
    o.duration_ps = parse_duration_ps(args.duration_given || !job ? args.duration : job_default, "--for");
    o.settle_ps = parse_duration_ps(args.settle, "--settle");
    for (const auto& pf : port_files(args.uart_in, "--uart-in")) o.uart_in.push_back({pf.port, pf.path});
    for (const auto& pf : port_files(args.uart_out, "--uart-out")) o.uart_out.push_back({pf.port, pf.path});
    o.read_uart_input = read_uart_input;
    o.skip_idle_loops = !args.no_idle_skip;
    o.predecoded_core = !args.simavr_core;
    o.translate_blocks = !args.no_block_translation;
    o.periodic_waves = !args.no_periodic_waves;
    o.job_port = args.host;
    if (!args.gcode.empty()) {
        BoardRunOptions::GcodeJob g;
        g.path = args.gcode;
        g.raw_bytes = args.gcode_bytes;
        g.flow = args.flow;
        g.family = args.family;
        g.error_patterns = args.error_patterns;
        g.line_timeout = args.line_timeout;
        g.wait_banner = args.wait_banner;
        if (!args.generic_boot.empty()) g.generic_boot_s = seconds_from_ps(parse_duration_ps(args.generic_boot, "--generic-boot"));
        for (const auto& item : args.realtime) g.realtime.push_back(parse_realtime_bytes(item, "--realtime"));
        o.gcode = g;
    } else if (!args.realtime.empty()) {
        for (const auto& item : args.realtime) parse_realtime_bytes(item, "--realtime");
        throw BadInput("--realtime needs --gcode (the bytes go to its host's port)");
    }
    if (!args.dxf.empty()) {
        if (!args.gcode.empty()) throw BadInput("--dxf and --gcode: give one job");
        o.more_files.input(args.dxf, "--dxf");
        if (!args.nc.empty()) o.more_files.output(args.nc, "--nc");
    }
    if (args.pace != "free" && args.pace != "realtime") throw BadInput("--pace: '" + args.pace + "' is not free or realtime");
    if (args.reset_on_open && args.pty.empty()) throw BadInput("--reset-on-open: needs --pty PORT (the port whose opening resets its MCU)");
    if (!args.pty.empty()) o.pty = BoardRunOptions::Pty{args.pty, args.pty_link, args.pace == "realtime", args.reset_on_open};
    o.vcd = args.vcd;
    o.vcd_layout = vcd_layout(args);
    o.report = args.report;
    o.profile = args.profile;
    o.trace = args.trace;
    o.trace_only = args.trace_only;
    o.on_progress = [&progress](double fraction, double simulated_s) { progress.show(fraction, simulated_s); };
    if (!args.status_every.empty()) {
        o.status_every_ps = ps_from_seconds(parse_quantity(args.status_every, Dimension::Time, "--status-every"), "--status-every");
        if (o.status_every_ps <= 0) throw BadInput("--status-every " + args.status_every + ": give a time above 0 (e.g. 5s)");
    }
    o.status_file = args.status_file;
    if (!args.status_file.empty()) o.more_files.output(args.status_file, "--status-file");
    // SIGUSR1 (kill -USR1 PID) asks for a status now, whatever the interval.
    static std::atomic<bool> status_signal{false};
    struct sigaction on_usr1 {};
    on_usr1.sa_handler = [](int) { status_signal.store(true, std::memory_order_relaxed); };
    sigemptyset(&on_usr1.sa_mask);
    sigaction(SIGUSR1, &on_usr1, nullptr);
    o.status_now = &status_signal;
    o.on_status = [](const std::string& line) {
        std::fprintf(stderr, "%s\n", line.c_str());
        std::fflush(stderr);
    };
    o.on_announce = [](const std::string& line) {
        std::printf("%s\n", line.c_str());
        std::fflush(stdout);
    };
    return o;
}

int run_board_command(const RunArgs& args) {
    ProgressBar progress(!args.quiet && isatty(STDERR_FILENO) != 0);
    BoardRunOptions options = board_run_options(args, progress);
    // The drawing is read once the board is built, as the library asks.
    if (!args.dxf.empty()) options.records = [&args] { return plot_job(args); };
    if (auto debug = debug_options(args)) {
        Debugger debugger(*debug);
        const auto run = run_board_debugged(options, debugger);
        progress.finish();
        for (const std::string& line : run->summary()) std::printf("%s\n", line.c_str());
        const int code = exit_code(debugged_verdict(debugger, run->verdict(args.strict)));
        debugger.run_ended(code);
        return code;
    }
    BoardRun run(std::move(options));
    run.run();
    progress.finish();
    for (const std::string& line : run.summary()) std::printf("%s\n", line.c_str());
    return exit_code(run.verdict(args.strict));
}

int run_command(const RunArgs& args) {
    if (!args.board.empty()) return run_board_command(args);
    if (!args.gcode.empty()) throw BadInput("--gcode needs --board (the board file names the serial port)");
    if (!args.status_every.empty() || !args.status_file.empty()) {
        throw BadInput(std::string(args.status_every.empty() ? "--status-file" : "--status-every") +
                       " needs --board (the status reports the board's axes and temperatures)");
    }
    if (!args.dxf.empty()) throw BadInput("--dxf needs --board (the board file names the serial port)");
    if (!args.report.empty()) throw BadInput("--report needs --board");
    if (!args.realtime.empty()) throw BadInput("--realtime needs --board and --gcode");
    McuRunOptions o;
    o.elf = args.elf;
    o.mcu_type = args.mcu;
    o.skip_idle_loops = !args.no_idle_skip;
    o.predecoded_core = !args.simavr_core;
    o.translate_blocks = !args.no_block_translation;
    if (!args.freq.empty()) o.frequency_hz = parse_frequency_hz(args.freq, "--freq");
    o.duration_ps = parse_duration_ps(args.duration, "--for");
    o.duration_text = args.duration;
    o.until_sleep = args.until_sleep;
    // Without a board there is one port: USART0 ("0=FILE" is accepted too).
    const std::vector<PortFile> uart_in = port_files(args.uart_in, "--uart-in");
    const std::vector<PortFile> uart_out = port_files(args.uart_out, "--uart-out");
    for (const auto* list : {&uart_in, &uart_out}) {
        for (const auto& pf : *list) {
            if (!pf.port.empty() && pf.port != "0") {
                throw BadInput("serial port '" + pf.port + "': without --board only USART0 is connected");
            }
        }
    }
    if (!uart_in.empty()) o.uart_in = uart_in.front().path;
    if (!uart_out.empty()) o.uart_out = uart_out.front().path;
    o.read_uart_input = read_uart_input;
    o.vcd = args.vcd;
    o.vcd_layout = vcd_layout(args);
    o.trace = args.trace;
    o.trace_only = args.trace_only;
    o.profile = args.profile;
    ProgressBar progress(!args.quiet && isatty(STDERR_FILENO) != 0);
    o.on_progress = [&progress](double fraction, double simulated_s) { progress.show(fraction, simulated_s); };
    if (auto debug = debug_options(args)) {
        if (args.until_sleep) throw BadInput("--until-sleep and --gdb: break where you want to stop instead");
        Debugger debugger(*debug);
        const auto run = run_mcu_debugged(o, debugger);
        progress.finish();
        for (const std::string& text : run->summary()) std::printf("%s\n", text.c_str());
        const int code = exit_code(debugged_verdict(debugger, run->verdict()));
        debugger.run_ended(code);
        return code;
    }
    McuRun run(std::move(o));
    run.run();
    progress.finish();
    for (const std::string& text : run.summary()) std::printf("%s\n", text.c_str());
    return exit_code(run.verdict());
}

}  // namespace

Command add_run_command(CLI::App& app) {
    auto args = std::make_shared<RunArgs>();
    RunArgs& run = *args;
    CLI::App* run_cmd = app.add_subcommand("run", "run a firmware ELF and record its pins");
    run_cmd->add_option("elf", run.elf, "firmware ELF (the file you would flash)")->required();
    run_cmd->add_option("--board", run.board, "board file (bench/boards/*.yaml): MCUs, parts, nets; ELF runs on its first MCU");
    run_cmd->add_option("--firmware", run.firmware, "MCU=ELF for a board's other MCUs (repeatable)");
    run_cmd->add_flag("--strict", run.strict, "part findings (driver timing, axis crashes) also give exit code 1");
    run_cmd->add_option("--mcu", run.mcu, "MCU type, e.g. atmega328p (default: from the ELF's .mmcu section)");
    run_cmd->add_option("--freq", run.freq, "clock, e.g. 16MHz (default: from the ELF's .mmcu section)");
    auto* trace_option = run_cmd->add_option(
        "--trace", run.trace,
        "pins to record besides the defaults: PB5,PD2 | PORTB | all; on a board MCU.PB5 for one MCU (defaults with "
        "--vcd: every pin and USART on one MCU; a board's nets, labels, serial ports, I2C and parts)");
    run_cmd->add_option("--trace-only", run.trace_only, "record only these pins, none of the defaults (same syntax as --trace)")
        ->excludes(trace_option);
    run_cmd->add_option("--vcd", run.vcd, "write the recorded signals as VCD (+ a .gtkw save file beside it)");
    run_cmd->add_option("--vcd-format", run.vcd_format,
                        "portable (default: 1-bit signals only, nets under their own codes: sigrok/PulseView read it; "
                        "the .gtkw joins bus bits again) | compact (vectors for buses, nets sharing their pin's code: smaller)")
        ->check(CLI::IsMember({"portable", "compact"}));
    run_cmd->add_option("--for", run.duration, "simulated time to run, e.g. 2s, 250ms (default 1s; with --gcode the limit for the job, default 60s)")
        ->each([&run](const std::string&) { run.duration_given = true; });
    run_cmd->add_option("--gcode", run.gcode, "stream this G-code file to the board's serial port (needs --board)");
    run_cmd->add_flag("--gcode-bytes", run.gcode_bytes,
                      "send --gcode's lines byte for byte, bytes that are not text included (how avrbench fuzz replays a reproducer)");
    run_cmd->add_option("--host", run.host, "the board's serial port for --gcode or --dxf (default: the first)");
    run_cmd->add_option("--dxf", run.dxf,
                        "plot this drawing (seed 002): CAM to G-code, binary records streamed stop-and-wait (needs --board)");
    run_cmd->add_option("--records", run.records, "--dxf: faithful | improved, as the firmware build expects (default faithful)");
    run_cmd->add_option("--feed", run.feed, "--dxf: drawing feed in mm/min (default 120)");
    run_cmd->add_option("--nc", run.nc, "--dxf: also write the G-code to this file");
    run_cmd->add_option("--pty", run.pty,
                        "PORT: bridge this serial port of the board to a pseudo-terminal for host software (prints its path)");
    run_cmd->add_option("--pty-link", run.pty_link, "--pty: also make a symlink to the pty here, e.g. traces/ttyUNO");
    run_cmd->add_flag("--reset-on-open", run.reset_on_open,
                      "--pty: reset the port's MCU whenever host software opens the pty, as an Arduino's auto-reset does");
    run_cmd->add_option("--status-every", run.status_every,
                        "a status line on stderr every this much simulated time (positions, steps, temperatures, findings "
                        "so far; kill -USR1 asks for one at any time)");
    run_cmd->add_option("--status-file", run.status_file, "the status as JSON, rewritten whole at each status line");
    run_cmd->add_option("--pace", run.pace,
                        "free (default: as fast as it runs) | realtime (simulated time never ahead of wall time)");
    run_cmd->add_option("--flow", run.flow, "send_and_wait | character_counting (default: the board's)");
    run_cmd->add_flag("--wait-banner", run.wait_banner, "send the job only after the firmware's first output line");
    run_cmd->add_option("--generic-boot", run.generic_boot,
                        "a generic firmware's port: send the job after its first output line, or after this long if it prints "
                        "none (how avrbench fuzz sends its inputs, e.g. 0.2s)");
    run_cmd->add_option("--family", run.family,
                        "grbl | marlin | prusa | teacup | repetier | sprinter | generic: the firmware's protocol on the "
                        "--host port, its welcome and error answers (default: the board's; docs/HOSTS.md)");
    run_cmd->add_option("--error-pattern", run.error_patterns,
                        "REGEX (RE2): a line the firmware prints that is an error, besides its family's own "
                        "(repeatable; needs --gcode)");
    run_cmd->add_option("--line-timeout", run.line_timeout,
                        "a line unanswered this long with no output at all and no STEP edge on the board is a timeout (default: the board's, else the family's: marlin 5s, teacup 2.5s, grbl and generic 2s; never under 2.5 times the keep-alive period seen)");
    run_cmd->add_option("--realtime", run.realtime,
                        "TIME=BYTES sent at that simulated time outside the line stream, e.g. 2s=! 4s=~ (grbl "
                        "feed hold/resume), 1s=^X, 3s=0x85 (repeatable; needs --gcode)");
    run_cmd->add_option("--settle", run.settle, "motion has stopped after no STEP edge for this long (default 50ms)");
    run_cmd->add_option("--report", run.report, "write an HTML report of the run (with --board)");
    run_cmd->add_option("--profile", run.profile,
                        "collect each MCU's timing profile (ISR time and latency, interrupts off, CPU load, stack "
                        "high-water mark): in the summary, and as JSON in this file (docs/CLI.md)");
    run_cmd->add_flag("--until-sleep", run.until_sleep, "stop when the firmware first executes SLEEP (bounded by --for)");
    run_cmd->add_option("--uart-in", run.uart_in,
                        "FILE or PORT=FILE: raw bytes to send to a serial port (the board's first, or USART0; repeatable)");
    run_cmd->add_option("--uart-out", run.uart_out,
                        "FILE or PORT=FILE: write what the firmware sent on a serial port (repeatable)");
    run_cmd->add_flag("-q,--quiet", run.quiet, "no progress bar");
    run_cmd->add_option("--gdb", run.gdb,
                        "[MCU=]PORT: wait for avr-gdb on 127.0.0.1:PORT (0: any free port, printed) and debug that MCU "
                        "(default the first); repeat for other MCUs of a board (docs/DEBUGGING.md)");
    run_cmd->add_flag("--break-at-finding", run.break_at_finding,
                      "--gdb: stop at each finding, at the instruction it came after (monitor findings says why)");
    run_cmd->add_option("--break-at", run.break_at, "--gdb: stop at the first instruction at or after this simulated time, e.g. 1.234s");
    run_cmd->add_option("--break-at-cycle", run.break_at_cycle, "--gdb: stop at the first instruction at or after this cycle");
    run_cmd->add_flag("--no-idle-skip", run.no_idle_skip,
                      "run every pass of the firmware's idle loops instead of jumping over them (same results, slower)");
    run_cmd->add_flag("--simavr-core", run.simavr_core,
                      "execute every instruction on simavr's own avr_run_one instead of the predecoded core "
                      "(same results, slower; kept for one release to compare)");
    run_cmd->add_flag("--no-block-translation", run.no_block_translation,
                      "interpret every instruction on the predecoded core instead of running straight runs of "
                      "register-only instructions as host code (same results, slower; to compare)");
    run_cmd->add_flag("--no-periodic-waves", run.no_periodic_waves,
                      "deliver every edge of a timer PWM through its net even when nothing records it "
                      "(heaters follow each edge instead of the mean power; slower)");

    return {run_cmd, [args] { return run_command(*args); }};
}

}  // namespace avrbench
