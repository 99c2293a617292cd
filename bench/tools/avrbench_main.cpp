// The avrbench command line. Thin by design: every step here is a library
// call that tests and other tools make the same way.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>
#include <vector>

#include "boards/Board.hpp"
#include "cam/Chain.hpp"
#include "cam/DxfReader.hpp"
#include "cam/Records.hpp"
#include "core/ElfImage.hpp"
#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "tools/FirmwareArgs.hpp"
#include "tools/FuzzCommand.hpp"
#include "core/Mcu.hpp"
#include "core/Units.hpp"
#include "core/Twi.hpp"
#include "core/UserStop.hpp"
#include "parts/Axis.hpp"
#include "parts/StepDirDriver.hpp"
#include "parts/ThermalPlant.hpp"
#include "core/OutputFile.hpp"
#include "trace/GtkwWriter.hpp"
#include "trace/WaveformFiles.hpp"
#include "trace/Junit.hpp"
#include "trace/Recorder.hpp"
#include "trace/HtmlReport.hpp"
#include "trace/VcdWriter.hpp"
#include "stimulus/PtyBridge.hpp"
#include "stimulus/RecordHost.hpp"
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
constexpr int kExitInterrupted = 130;  // 128 + SIGINT

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
    std::string gcode;
    bool gcode_bytes = false;  // --gcode-bytes: no text check (fuzzing reproducers)
    std::string host;
    std::string flow;
    bool wait_banner = false;
    std::string settle = "50ms";
    std::string report;
    std::string family;        // --family: overrides the board's
    std::string line_timeout;  // --line-timeout: overrides the board's
    std::vector<std::string> realtime;  // --realtime TIME=BYTES (repeatable)
    bool no_idle_skip = false;          // --no-idle-skip: run every pass of idle loops
    bool no_periodic_waves = false;     // --no-periodic-waves: every PWM edge through the nets
};

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

void print_findings(const std::vector<Finding>& findings) {
    std::printf("  findings   %zu\n", findings.size());
    for (const auto& line : summarize_findings(findings)) std::printf("    %s\n", line.c_str());
}

// Every file a run reads and writes, checked together before the run starts
// (core/OutputFile.hpp, RunFiles): each output a file of its own, none an input.
void check_run_files(const RunArgs& args, const std::vector<PortFile>& uart_in, const std::vector<PortFile>& uart_out,
                     const std::vector<std::string>& more_inputs = {}) {
    RunFiles files;
    files.input(args.elf, "the firmware ELF");
    for (const auto& f : more_inputs) files.input(f, "an input of the board");
    if (!args.gcode.empty()) files.input(args.gcode, "--gcode");
    if (!args.dxf.empty()) files.input(args.dxf, "--dxf");
    for (const auto& pf : uart_in) {
        if (pf.path != "-") files.input(pf.path, "--uart-in");
    }
    if (!args.vcd.empty()) {
        files.output(args.vcd, "--vcd");
        files.output(with_extension(args.vcd, ".gtkw"), "--vcd's gtkwave save file");
    }
    if (!args.report.empty()) files.output(args.report, "--report");
    for (const auto& pf : uart_out) files.output(pf.path, "--uart-out");
    if (!args.nc.empty()) files.output(args.nc, "--nc");
    files.check();
}

void print_text_tail(const std::string& text, std::size_t max_lines) {
    std::vector<std::string> lines;
    std::string line;
    for (char c : text) {
        if (c == '\n') {
            lines.push_back(line);
            line.clear();
        } else if (c != '\r') {
            line.push_back(c);
        }
    }
    if (!line.empty()) lines.push_back(line);
    const std::size_t from = lines.size() > max_lines ? lines.size() - max_lines : 0;
    for (std::size_t i = from; i < lines.size(); ++i) std::printf("    %s\n", hex_escaped(lines[i]).c_str());
}

// A crash of the firmware (the MCU's own oracles); part, net and host findings
// fail a run only with --strict.
// --trace: the recorder's error, named after the option that gave the list.
void trace_pins_for_cli(Recorder& recorder, Mcu& mcu, const std::string& spec, const char* option = "--trace") {
    try {
        recorder.trace_pins(mcu, spec);
    } catch (const BadInput& e) {
        throw BadInput(std::string(option) + ": " + e.what());
    }
}

// On a board: PB5, PORTB or all name pins of every MCU; MCU.PB5, MCU.PORTB
// or MCU.all those of one MCU.
void trace_board_pins_for_cli(Recorder& recorder, Board& board, const std::string& spec, const char* option) {
    if (spec.empty()) return;
    std::string every_mcu;
    std::map<std::string, std::string> per_mcu;
    std::stringstream items(spec);
    std::string item;
    while (std::getline(items, item, ',')) {
        const auto dot = item.find('.');
        if (dot == std::string::npos) {
            every_mcu += item + ",";
            continue;
        }
        const std::string mcu = item.substr(0, dot);
        if (board.spec().find_mcu(mcu) == nullptr)
            throw BadInput(std::string(option) + ": '" + item + "': the board has no MCU '" + mcu + "'");
        per_mcu[mcu] += item.substr(dot + 1) + ",";
    }
    for (Mcu* m : board.mcus()) {
        if (!every_mcu.empty()) trace_pins_for_cli(recorder, *m, every_mcu, option);
        if (const auto it = per_mcu.find(m->name()); it != per_mcu.end()) trace_pins_for_cli(recorder, *m, it->second, option);
    }
}

// --realtime 2.5s='!': a time and the bytes to send then, outside the line
// stream: printable characters as they are, ^X for a control character
// (grbl's soft reset Ctrl-X), 0xNN for any byte (grbl 1.1's overrides).
std::pair<Picoseconds, std::string> parse_realtime(const std::string& item) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq + 1 >= item.size()) {
        throw BadInput("--realtime '" + item + "': expected TIME=BYTES, e.g. 2s=! or 1.5s=^X or 3s=0x85");
    }
    const Picoseconds at = parse_duration_ps(item.substr(0, eq), "--realtime");
    const std::string text = item.substr(eq + 1);
    std::string bytes;
    if (text.size() == 2 && text[0] == '^' && text[1] >= '@' && text[1] <= '_') {
        bytes.push_back(static_cast<char>(text[1] - '@'));
    } else if (text.size() == 4 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X') &&
               std::isxdigit(static_cast<unsigned char>(text[2])) && std::isxdigit(static_cast<unsigned char>(text[3]))) {
        bytes.push_back(static_cast<char>(std::stoi(text.substr(2), nullptr, 16)));
    } else {
        for (char c : text) {
            if (c < 0x20 || c > 0x7e) throw BadInput("--realtime '" + item + "': write control bytes as ^X or 0xNN");
        }
        bytes = text;
    }
    return {at, bytes};
}

// A finding that fails every run (the firmware crashed or reset), not only --strict ones.
bool fails_every_run(const Finding& f) { return f.kind.severity() == Severity::Error; }

// How much of the run the idle-loop skipper covered (core/IdleLoopSkip.hpp).
void print_idle_skip(const Mcu& mcu, bool name_it) {
    if (mcu.idle_jumps() == 0) return;
    std::printf("  idle skip  %s%llu jumps over %.6f s of idle-loop passes\n",
                name_it ? (mcu.name() + ": ").c_str() : "", static_cast<unsigned long long>(mcu.idle_jumps()),
                static_cast<double>(mcu.idle_cycles_skipped()) / mcu.frequency_hz());
}

// What `run --board` sets up from its arguments, all checked before anything runs.
struct BoardRun {
    std::unique_ptr<Bench> bench;
    UartHost* host = nullptr;  // --gcode's
    std::unique_ptr<RecordHost> plot;  // --dxf's
    std::unique_ptr<PtyBridge> pty;    // --pty's
    Mcu* pty_mcu = nullptr;            // the MCU behind it
    unsigned resets_on_open = 0;
    std::vector<PortFile> uart_out;
    Picoseconds duration_ps = 0, settle_ps = 0;
    // I2C traffic per master MCU, for the summary.
    struct I2cCount {
        std::uint64_t transfers = 0, bytes = 0, nacks = 0;
    };
    std::map<std::string, std::shared_ptr<I2cCount>> i2c;
};

BoardRun prepare_board_run(const RunArgs& args) {
    if (!args.mcu.empty() || !args.freq.empty()) {
        throw BadInput("--mcu/--freq do not apply with --board: the board file gives each MCU's type and clock");
    }
    BoardSpec spec = load_board_file(args.board);
    std::map<std::string, std::string> firmware = firmware_assignments(args.firmware);
    firmware[spec.mcus.front().name] = args.elf;
    BoardRun run;
    // With a job, --for is the limit for finishing it (default 60 s; a plot 600 s).
    const char* job_default = !args.dxf.empty() ? "600s" : "60s";
    const bool job = !args.gcode.empty() || !args.dxf.empty();
    run.duration_ps = parse_duration_ps(args.duration_given || !job ? args.duration : job_default, "--for");
    run.settle_ps = parse_duration_ps(args.settle, "--settle");
    const std::vector<PortFile> uart_in = port_files(args.uart_in, "--uart-in");
    run.uart_out = port_files(args.uart_out, "--uart-out");
    {
        std::vector<std::string> board_inputs = {spec.path};
        for (const auto& [mcu, elf] : firmware) board_inputs.push_back(elf);
        for (const auto& m : spec.mcus) board_inputs.push_back(m.bootloader);
        check_run_files(args, uart_in, run.uart_out, board_inputs);
    }
    std::vector<std::pair<std::string, std::string>> uart_in_bytes;  // port -> bytes
    for (const auto& pf : uart_in) uart_in_bytes.emplace_back(pf.port, read_uart_input(pf.path));
    if (!args.gcode.empty()) check_input_file(args.gcode, "--gcode", kMaxGcodeFileBytes);

    run.bench = std::make_unique<Bench>(std::move(spec), firmware);
    Bench& bench = *run.bench;
    Board& board = bench.board();
    for (Mcu* m : board.mcus()) m->set_skip_idle_loops(!args.no_idle_skip);
    if (args.no_periodic_waves) board.set_periodic_waves(false);
    if (board.spec().serial.empty() && (!uart_in.empty() || !run.uart_out.empty() || job)) {
        throw BadInput(args.board + ": the board declares no serial port (needed by --gcode, --dxf, --uart-in, --uart-out)");
    }
    // Resolve every named port now, so a typo fails before the run.
    for (const auto& pf : uart_in) bench.serial_decl(pf.port);
    for (const auto& pf : run.uart_out) bench.serial_decl(pf.port);
    if (!args.host.empty()) bench.serial_decl(args.host);

    std::vector<std::pair<Picoseconds, std::string>> realtime_bytes;
    for (const auto& item : args.realtime) realtime_bytes.push_back(parse_realtime(item));
    if (!args.gcode.empty()) {
        const SerialDecl& decl = bench.serial_decl(args.host);
        for (const auto& pf : uart_in) {
            if (bench.serial_decl(pf.port).name == decl.name) {
                throw BadInput("--uart-in: port " + decl.name + " already streams --gcode; give another port (PORT=FILE)");
            }
        }
        UartHostOptions o = default_host_options(decl);
        if (!args.flow.empty()) o.flow = parse_flow_control(args.flow, "--flow");
        if (!args.family.empty()) o.family = parse_firmware_family(args.family, "--family");
        if (!args.line_timeout.empty()) {
            o.line_timeout_s = seconds_from_ps(parse_duration_ps(args.line_timeout, "--line-timeout"));
            if (!(o.line_timeout_s > 0)) throw BadInput("--line-timeout: must be longer than 0");
        }
        if (args.wait_banner) o.startup = Startup::WaitForBanner;
        run.host = &bench.host(decl.name, o);
        if (args.gcode_bytes) {
            // The file's bytes as lines, as avrbench fuzz sent them: binary bytes included.
            run.host->add_lines(read_input_file(args.gcode, "--gcode", kMaxGcodeFileBytes));
        } else {
            run.host->load_file(args.gcode);
        }
        for (const auto& [at_ps, bytes] : realtime_bytes) {
            run.host->send_bytes_at(bytes, board.mcu(decl.mcu).cycles_from_seconds(seconds_from_ps(at_ps)));
        }
    } else if (!realtime_bytes.empty()) {
        throw BadInput("--realtime needs --gcode (the bytes go to its host's port)");
    }
    if (!args.dxf.empty()) {
        if (!args.gcode.empty()) throw BadInput("--dxf and --gcode: give one job");
        if (args.records != "faithful" && args.records != "improved") {
            throw BadInput("--records: '" + args.records + "' is not faithful or improved");
        }
        const double feed = parse_quantity(args.feed, Dimension::Dimensionless, "--feed");
        if (!(feed > 0 && feed <= 1e5)) throw BadInput("--feed: mm/min above 0 and at most 100000");
        Drawing drawing = read_dxf(args.dxf).drawing;
        align_segments(drawing, 0.01);
        const GcodeProgram gcode = emit_gcode(drawing, 0.01, feed);
        if (!args.nc.empty()) write_output_file(args.nc, gcode.text, "--nc");
        RecordOptions options;
        options.improved = args.records == "improved";
        const RecordProgram program = records_from_gcode(gcode.text, options, args.dxf);
        Uart& port = bench.serial(args.host);
        run.plot = std::make_unique<RecordHost>(board.mcu(bench.serial_decl(args.host).mcu), port, program.messages,
                                                RecordHost::Options{}, program.busy_seconds);
        run.plot->start();
    }
    for (const auto& [port, bytes] : uart_in_bytes) bench.serial(port).send(bytes);
    if (args.pace != "free" && args.pace != "realtime") throw BadInput("--pace: '" + args.pace + "' is not free or realtime");
    if (args.reset_on_open && args.pty.empty()) throw BadInput("--reset-on-open: needs --pty PORT (the port whose opening resets its MCU)");
    if (!args.pty.empty()) {
        const SerialDecl& decl = bench.serial_decl(args.pty);
        if (!args.gcode.empty() || !args.dxf.empty()) {
            if (bench.serial_decl(args.host).name == decl.name) throw BadInput("--pty: port " + decl.name + " already carries the job");
        }
        run.pty = std::make_unique<PtyBridge>(bench.serial(decl.name), args.pty_link);
        run.pty_mcu = &bench.mcu(decl.mcu);
        // At once, so a host can connect while the run goes on.
        std::printf("avrbench run: serial %s on %s%s%s\n", decl.name.c_str(), run.pty->path().c_str(),
                    args.pty_link.empty() ? "" : " = ", args.pty_link.c_str());
        std::fflush(stdout);
    }
    for (Mcu* m : board.mcus()) {
        Twi* twi = m->twi();
        if (twi == nullptr) continue;
        for (const auto& bus : board.twi_buses()) {
            if (&twi->bus() != bus.get() || bus->members().size() < 2) continue;
            auto count = std::make_shared<BoardRun::I2cCount>();
            run.i2c[m->name()] = count;
            // NACKs of the slaves (address, written bytes); a master receiver
            // NACKs the last byte it reads by design.
            auto reading = std::make_shared<bool>(false);
            twi->on_event([count, reading](const TwiEvent& e) {
                if (e.kind == TwiEvent::Kind::Address) {
                    ++count->transfers;
                    *reading = (e.byte & 1) != 0;
                    if (!e.acked) ++count->nacks;
                } else if (e.kind == TwiEvent::Kind::Data) {
                    ++count->bytes;
                    if (!*reading && !e.acked) ++count->nacks;
                }
            });
        }
    }
    if (!args.vcd.empty() || !args.report.empty()) {
        if (args.trace_only.empty()) bench.trace_board();
        trace_board_pins_for_cli(bench.recorder(), board, args.trace_only.empty() ? args.trace : args.trace_only,
                                 args.trace_only.empty() ? "--trace" : "--trace-only");
    }
    return run;
}

void print_board_summary(const RunArgs& args, BoardRun& run, IdleResult outcome, double wall_s,
                         const std::vector<Finding>& findings, const std::string& gtkw_path) {
    Bench& bench = *run.bench;
    Board& board = bench.board();
    const double simulated_s = bench.now_seconds();
    std::printf("avrbench run: board %s (%s)\n", board.spec().name.c_str(), args.board.c_str());
    for (Mcu* m : board.mcus()) {
        std::printf("  mcu        %s: %s at %.6g MHz, firmware %s%s\n", m->name().c_str(), m->mcu_type().c_str(),
                    m->frequency_hz() / 1e6, m->elf().path().c_str(), m->halted() ? " (halted)" : "");
    }
    for (Mcu* m : board.mcus()) {
        if (!m->boot()) continue;
        std::printf("  boot       %s: %s at 0x%05X (%u bytes), started the application %u time%s; the application section %s\n",
                    m->name().c_str(), m->bootloader_path().c_str(), m->boot()->start_bytes, m->boot()->size_bytes,
                    m->application_starts(), m->application_starts() == 1 ? "" : "s",
                    m->elf_matches_flash() ? "holds the ELF" : "now differs from the ELF (rewritten by the boot loader)");
    }
    std::printf("  simulated  %.6f s\n", simulated_s);
    std::printf("  wall       %.3f s, real-time factor %.1fx\n", wall_s, wall_s > 0 ? simulated_s / wall_s : 0.0);
    for (Mcu* m : board.mcus()) print_idle_skip(*m, board.mcus().size() > 1);
    if (run.pty) {
        std::printf("  pty        %s: %llu bytes to the firmware, %llu from it%s", run.pty->path().c_str(),
                    static_cast<unsigned long long>(run.pty->bytes_to_firmware()),
                    static_cast<unsigned long long>(run.pty->bytes_to_host()),
                    run.pty->bytes_dropped() != 0 ? " (the host did not read them all)" : "");
        if (args.reset_on_open) std::printf(", %u resets on open", run.resets_on_open);
        std::printf("\n");
    }
    if (run.plot) {
        std::printf("  plot       %s: %zu of %zu records acknowledged (%s)%s\n", args.dxf.c_str(), run.plot->acknowledged(),
                    run.plot->messages(), args.records.c_str(), run.plot->failed() ? ", failed" : "");
    }
    if (run.host != nullptr) {
        std::printf("  job        %s: %zu of %zu lines acknowledged (%zu ok, %zu error), %s\n", args.gcode.c_str(),
                    run.host->lines_acknowledged(), run.host->lines().size(), run.host->oks(), run.host->errors(),
                    to_string(outcome));
    }
    for (const auto& [mcu, count] : run.i2c) {
        if (count->transfers == 0) continue;  // a master that never spoke is no master
        std::printf("  i2c        %s as master: %llu transfers, %llu data bytes, %llu NACKed by a slave\n", mcu.c_str(),
                    static_cast<unsigned long long>(count->transfers), static_cast<unsigned long long>(count->bytes),
                    static_cast<unsigned long long>(count->nacks));
    }
    for (Part* part : board.parts()) {
        if (const std::string line = part->summary(); !line.empty()) std::printf("  %s\n", line.c_str());
    }
    print_findings(findings);
    if (run.host != nullptr) {
        std::printf("  transcript (last lines):\n");
        print_text_tail(run.host->tail(10), 10);
    }
    for (const auto& decl : board.spec().serial) {
        if ((run.host != nullptr || run.plot) && bench.serial_decl(args.host).name == decl.name) continue;
        const Uart& u = bench.serial(decl.name);
        std::printf("  serial %-4s %zu bytes from firmware, %llu bytes to firmware%s\n", decl.name.c_str(),
                    u.transmitted().size(), static_cast<unsigned long long>(u.bytes_delivered()),
                    u.transmitted().empty() ? "" : "; last lines:");
        print_text_tail(u.transmitted_text(), 10);
    }
    if (!args.vcd.empty()) {
        const Timeline& timeline = bench.timeline();
        std::printf("  vcd        %s (%zu signals, %llu events), gtkwave save file %s\n", args.vcd.c_str(),
                    timeline.signals().size(), static_cast<unsigned long long>(timeline.recorded_count()),
                    gtkw_path.c_str());
    }
    if (!args.report.empty()) std::printf("  report     %s\n", args.report.c_str());
}

// The exit code (docs/CLI.md), with the one-line reason on stderr.
int board_exit_code(const RunArgs& args, const BoardRun& run, IdleResult outcome, const std::vector<Finding>& findings) {
    for (const auto& f : findings) {
        if (fails_every_run(f) || (args.strict && f.kind != UartHost::kHostProtocol)) return kExitFinding;
    }
    if (run.plot && run.plot->failed()) {
        std::fprintf(stderr, "avrbench: timeout: %s\n", run.plot->failure().c_str());
        return kExitTimeout;
    }
    if (outcome == IdleResult::Interrupted) {
        std::fprintf(stderr, "avrbench: interrupted at %.6f s simulated; what was recorded is written\n",
                     run.bench->now_seconds());
        return kExitInterrupted;
    }
    if (run.host != nullptr && outcome == IdleResult::HostFailed) {
        std::fprintf(stderr, "avrbench: %s\n", run.host->failure_message().c_str());
        // A host that got no answer is a timeout; error/ALARM/!! are findings.
        bool timed_out = false;
        for (const auto& e : run.host->events()) {
            timed_out = timed_out || e.kind == HostEventKind::Timeout || e.kind == HostEventKind::BannerTimeout;
        }
        return timed_out ? kExitTimeout : kExitFinding;
    }
    if (run.host != nullptr && outcome == IdleResult::TimeLimit) {
        std::fprintf(stderr, "avrbench: timeout: the job was not finished within %g s (%zu of %zu lines acknowledged)\n",
                     seconds_from_ps(run.duration_ps), run.host->lines_acknowledged(), run.host->lines().size());
        return kExitTimeout;
    }
    if (args.strict) {
        for (const auto& f : findings) {
            if (f.kind == UartHost::kHostProtocol) return kExitFinding;
        }
    }
    return kExitOk;
}

int run_board_command(const RunArgs& args) {
    BoardRun run = prepare_board_run(args);
    Bench& bench = *run.bench;
    std::vector<std::string> mcu_scopes;
    for (Mcu* m : bench.board().mcus()) mcu_scopes.push_back(m->name());
    WaveformFiles waveforms(bench.timeline(), args.vcd, args.report.empty(), vcd_layout(args), mcu_scopes);
    waveforms.start();
    ProgressBar progress(!args.quiet && isatty(STDERR_FILENO) != 0);
    const auto wall_start = std::chrono::steady_clock::now();
    Bench::RunSlices how;
    how.until_idle = run.host != nullptr;
    if (run.plot) how.stop_when = [&run] { return run.plot->failed(); };
    how.settle_ps = run.settle_ps;
    // A host on a pty at real time waits for each answer: 1 ms slices keep
    // the round trip near the UART's own (a 128-byte page at 115200 baud is
    // 11 ms; with 10 ms slices avrdude took 9.4 s to write grbl instead of ~5).
    if (run.pty && args.pace == "realtime") how.slice_ps = kPsPerMs;
    how.after_slice = [&] {
        if (run.pty) {
            if (run.pty->host_opened() && args.reset_on_open) {
                // What an Arduino's DTR capacitor does when the host opens the port.
                run.pty_mcu->reset_external();
                ++run.resets_on_open;
            }
            run.pty->pump();
            if (args.pace == "realtime") {
                // Simulated time no further than wall time (the host's timeouts are in seconds).
                const auto due = wall_start + std::chrono::nanoseconds(bench.now_ps() / 1000);
                std::this_thread::sleep_until(due);
            }
        }
        waveforms.drain(bench.now_ps());
        progress.show(static_cast<double>(bench.now_ps()) / static_cast<double>(run.duration_ps), bench.now_seconds());
    };
    const IdleResult outcome = bench.run_to_ps(run.duration_ps, how);
    progress.finish();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

    if (bench.timeline().overflowed()) throw BadInput(bench.timeline().overflow_message());
    const std::string gtkw_path = waveforms.finish(bench.mcu().cycle(), bench.mcu().frequency_hz());
    for (const auto& pf : run.uart_out) write_output_file(pf.path, bench.serial(pf.port).transmitted_text(), "--uart-out");
    const auto findings = bench.findings();
    if (!args.report.empty()) {
        write_html_report(bench.make_report(std::string(bench.mcu().elf().path()) + " on " + bench.board().spec().name),
                          args.report);
    }
    print_board_summary(args, run, outcome, wall_s, findings, gtkw_path);
    return board_exit_code(args, run, outcome, findings);
}

int run_command(const RunArgs& args) {
    if (!args.board.empty()) return run_board_command(args);
    if (!args.gcode.empty()) throw BadInput("--gcode needs --board (the board file names the serial port)");
    if (!args.dxf.empty()) throw BadInput("--dxf needs --board (the board file names the serial port)");
    if (!args.report.empty()) throw BadInput("--report needs --board");
    if (!args.realtime.empty()) throw BadInput("--realtime needs --board and --gcode");
    const ElfImage elf = ElfImage::load(args.elf);
    McuOptions options;
    options.name = "mcu";
    options.mcu_type = args.mcu;
    options.skip_idle_loops = !args.no_idle_skip;
    if (!args.freq.empty()) options.frequency_hz = parse_frequency_hz(args.freq, "--freq");
    const Picoseconds duration_ps = parse_duration_ps(args.duration, "--for");
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
    check_run_files(args, uart_in, uart_out);
    std::string uart_in_bytes;
    if (!uart_in.empty()) uart_in_bytes = read_uart_input(uart_in.front().path);

    Mcu mcu(elf, options);
    Timeline timeline;
    Recorder recorder(timeline);
    const bool tracing = !args.vcd.empty() || !args.trace.empty() || !args.trace_only.empty();
    // The default on one MCU is every pin; --trace only checks its names then.
    if (tracing && !args.trace.empty()) trace_pins_for_cli(recorder, mcu, args.trace);
    if (tracing) trace_pins_for_cli(recorder, mcu, args.trace_only.empty() ? "all" : args.trace_only, "--trace-only");

    Uart* uart0 = nullptr;
    try {
        uart0 = &mcu.uart(0);
    } catch (const BadInput&) {
        if (!args.uart_in.empty() || !args.uart_out.empty()) throw;
    }
    if (uart0 != nullptr && tracing && args.trace_only.empty()) {
        recorder.trace_uart_tx(mcu, *uart0);
        recorder.trace_uart_rx(mcu, *uart0);
    }
    if (!uart_in_bytes.empty()) uart0->send(uart_in_bytes);

    const Cycle end_cycle = cycle_at_ps(mcu, duration_ps);
    WaveformFiles waveforms(timeline, args.vcd, true, vcd_layout(args));
    waveforms.start();
    ProgressBar progress(!args.quiet && isatty(STDERR_FILENO) != 0);
    const auto wall_start = std::chrono::steady_clock::now();
    bool slept = false;
    if (args.until_sleep) {
        slept = mcu.run_until_sleep(end_cycle);
    } else {
        mcu.run_sliced(end_cycle, [&] {
            waveforms.drain(ps_at_cycle(mcu, mcu.cycle()));
            progress.show(static_cast<double>(mcu.cycle()) / static_cast<double>(end_cycle), mcu.seconds());
        });
    }
    progress.finish();
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

    if (!uart_out.empty()) write_output_file(uart_out.front().path, uart0->transmitted_text(), "--uart-out");
    if (timeline.overflowed()) throw BadInput(timeline.overflow_message());
    const std::string gtkw_path = waveforms.finish(mcu.cycle(), mcu.frequency_hz());

    const double simulated_s = mcu.seconds();
    std::printf("avrbench run: %s on %s at %.6g MHz\n", args.elf.c_str(), mcu.mcu_type().c_str(),
                mcu.frequency_hz() / 1e6);
    std::printf("  simulated  %.6f s (%llu cycles)\n", simulated_s, static_cast<unsigned long long>(mcu.cycle()));
    std::printf("  wall       %.3f s, real-time factor %.1fx\n", wall_s, wall_s > 0 ? simulated_s / wall_s : 0.0);
    print_idle_skip(mcu, false);
    if (args.until_sleep) std::printf("  stopped    %s\n", slept ? "firmware executed SLEEP" : "time limit");
    if (mcu.halted()) std::printf("  halted     %s\n", mcu.halt_reason().c_str());
    if (uart0 != nullptr) {
        std::printf("  uart0      %zu bytes from firmware, %llu bytes to firmware\n", uart0->transmitted().size(),
                    static_cast<unsigned long long>(uart0->bytes_delivered()));
    }
    print_findings(mcu.findings());
    if (!args.vcd.empty()) {
        std::printf("  vcd        %s (%zu signals, %llu events), gtkwave save file %s\n", args.vcd.c_str(),
                    timeline.signals().size(), static_cast<unsigned long long>(timeline.recorded_count()),
                    gtkw_path.c_str());
    }
    if (user_stop_requested()) {
        std::fprintf(stderr, "avrbench: interrupted at %.6f s simulated; what was recorded is written\n", simulated_s);
        return kExitInterrupted;
    }
    if (!mcu.findings().empty()) return kExitFinding;
    if (args.until_sleep && !slept && !mcu.halted()) {
        std::fprintf(stderr, "avrbench: timeout: the firmware did not execute SLEEP within %s\n", args.duration.c_str());
        return kExitTimeout;
    }
    return kExitOk;
}

// `avrbench findings`: every finding kind the linked layers and parts declare.
int findings_command() {
    std::size_t width = 0;
    for (const FindingKind kind : FindingKind::all()) width = std::max(width, kind.name().size());
    std::printf("Finding kinds (error: fails every run; warning: fails under --strict)\n");
    for (const FindingKind kind : FindingKind::all()) {
        std::printf("  %-*s  %-7s  %s\n", static_cast<int>(width), kind.name().c_str(), to_string(kind.severity()),
                    kind.meaning().c_str());
    }
    return kExitOk;
}

// `avrbench boards`: the standard boards a bare name selects, with their descriptions.
int boards_command() {
    const std::vector<StandardBoard> boards = list_standard_boards();
    if (boards.empty()) {
        throw BadInput("no standard boards found (looked in: $AVRBENCH_BOARDS_DIR, <prefix>/share/avrbench/boards, the source tree)");
    }
    std::size_t width = 0;
    for (const auto& b : boards) width = std::max(width, b.name.size());
    std::printf("Standard boards (run --board NAME, or `board: NAME` in a scenario); files in %s\n",
                std::filesystem::path(boards.front().path).parent_path().string().c_str());
    for (const auto& b : boards) {
        std::printf("  %-*s  %s\n", static_cast<int>(width), escaped(b.name).c_str(),
                    escaped(b.error.empty() ? b.description : "(does not load: " + b.error + ")").c_str());
    }
    return kExitOk;
}

struct CamArgs {
    std::string dxf;
    std::string out;            // .nc file ("" = beside the DXF)
    std::string tolerance = "0.01mm";
    std::string feed = "600";   // mm/min
};

// DXF -> aligned segments -> G-code (seed 002's CAD2G, docs/CNC.md).
int cam_command(const CamArgs& args) {
    const std::string out = args.out.empty() ? with_extension(args.dxf, ".nc") : args.out;
    RunFiles files;
    files.input(args.dxf, "the drawing");
    files.output(out, args.out.empty() ? "the G-code (the DXF's name with .nc)" : "-o");
    files.check();
    DxfReadResult read = read_dxf(args.dxf);
    const double tolerance_mm = parse_quantity(args.tolerance, Dimension::Length, "--tolerance") * 1e3;
    if (!(tolerance_mm >= 0 && tolerance_mm <= 10)) throw BadInput("--tolerance: must be from 0 to 10 mm");
    const double feed = parse_quantity(args.feed, Dimension::Dimensionless, "--feed");
    if (!(feed > 0 && feed <= 1e5)) throw BadInput("--feed: mm/min above 0 and at most 100000");
    const GcodeProgram before = emit_gcode(read.drawing, tolerance_mm, feed);
    const ChainStats stats = align_segments(read.drawing, tolerance_mm);
    const GcodeProgram after = emit_gcode(read.drawing, tolerance_mm, feed);
    write_output_file(out, after.text, "-o");
    std::printf("avrbench cam: %s\n", args.dxf.c_str());
    std::printf("  entities   %zu (lines, arcs, circles); %u others skipped\n", read.drawing.segments.size(),
                read.skipped_entities);
    std::printf("  aligned    %u passes, tolerance %g mm\n", stats.revisions, tolerance_mm);
    std::printf("  commands   %u -> %u (rapids %u -> %u)\n", before.commands, after.commands, before.rapids, after.rapids);
    std::printf("  g-code     %s\n", out.c_str());
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
    bool force = false;
    std::vector<std::string> scenarios;
    std::string junit;
    std::string report_dir;
    std::string vcd_dir;
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

JunitCase junit_case(const ScenarioResult& r) {
    JunitCase c;
    c.name = r.name;
    c.time_s = r.wall_s;
    c.outcome = r.error ? JunitCase::Outcome::Error : r.passed ? JunitCase::Outcome::Passed : JunitCase::Outcome::Failed;
    c.message = r.failures.empty() ? "" : r.failures.front();
    c.text = r.text();
    return c;
}

// Runs every scenario it is given: one that cannot load or run is an error
// result (its file:line message in the output and the JUnit file), never the
// end of the batch. Exit: 2 if any scenario had an error, else 1 if any
// failed (or, updating goldens, was refused), else 0.
int check_command(const CheckArgs& args, bool update_golden) {
    const std::string firmware_dir = args.firmware_dir.empty() ? default_firmware_dir() : args.firmware_dir;
    // The report folder first: it is ours to create, and --junit may point into it.
    if (!args.report_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(args.report_dir, ec);
        if (ec || !std::filesystem::is_directory(args.report_dir, ec)) {
            throw BadInput("--report-dir: " + args.report_dir + ": cannot create the folder");
        }
    }
    if (!args.vcd_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(args.vcd_dir, ec);
        if (ec || !std::filesystem::is_directory(args.vcd_dir, ec)) {
            throw BadInput("--vcd-dir: " + args.vcd_dir + ": cannot create the folder");
        }
    }
    if (!args.junit.empty()) check_output_path(args.junit, "--junit");
    ScenarioRunOptions options;
    options.report_dir = args.report_dir;
    options.vcd_dir = args.vcd_dir;
    options.update_golden = update_golden;
    options.force = args.force;
    std::vector<ScenarioResult> results;
    for (const auto& path : update_golden ? args.scenarios : shard(args.scenarios)) {
        if (user_stop_requested()) break;
        try {
            const ScenarioSpec spec = load_scenario(path, firmware_dir);
            results.push_back(run_scenario(spec, options));
            if (update_golden && results.back().passed && !spec.golden_path.empty()) {
                std::printf("%s: golden timeline written to %s (%.3f s simulated)\n", spec.name.c_str(),
                            spec.golden_path.c_str(), results.back().simulated_s);
                continue;
            }
            if (update_golden && results.back().passed) {
                std::printf("%s: no golden timeline (the scenario names none)\n", spec.name.c_str());
                continue;
            }
        } catch (const BadInput& e) {
            results.push_back(error_result(path, escaped(e.what())));
            std::fflush(stdout);
            std::fprintf(stderr, "avrbench: error: %s\n", escaped(e.what()).c_str());
        }
        std::fputs(results.back().text().c_str(), stdout);
    }
    if (!args.junit.empty()) {
        std::vector<JunitCase> cases;
        for (const auto& r : results) cases.push_back(junit_case(r));
        write_output_file(args.junit, junit_xml(cases, "avrbench"), "--junit");
    }
    std::size_t failed = 0, errors = 0;
    for (const auto& r : results) {
        errors += r.error ? 1 : 0;
        failed += !r.error && !r.passed ? 1 : 0;
    }
    if (errors > 0) std::printf("%zu scenario(s) could not be loaded or run (ERROR above)\n", errors);
    if (user_stop_requested()) {
        std::printf("%zu passed, %zu failed\n", results.size() - failed - errors, failed + errors);
        std::fprintf(stderr, "avrbench: interrupted after %zu scenario(s); their results are written\n", results.size());
        return kExitInterrupted;
    }
    std::printf("%zu passed, %zu failed\n", results.size() - failed - errors, failed + errors);
    return errors > 0 ? kExitBadInput : failed > 0 ? kExitFinding : kExitOk;
}

// `--vcd ''` is a mistake, not "no VCD": an option that takes a value and
// was given an empty one is bad usage, for every option of every command.
void reject_empty_values(const CLI::App& app) {
    for (const CLI::App* command : app.get_subcommands()) {
        for (const CLI::Option* option : command->get_options()) {
            if (option->count() == 0 || option->get_type_size() == 0) continue;  // not given, or a flag
            for (const std::string& value : option->results()) {
                if (value.empty()) throw BadInput(option->get_name() + ": an empty value");
            }
        }
        reject_empty_values(*command);
    }
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
    run_cmd->add_option("--pace", run.pace,
                        "free (default: as fast as it runs) | realtime (simulated time never ahead of wall time)");
    run_cmd->add_option("--flow", run.flow, "send_and_wait | character_counting (default: the board's)");
    run_cmd->add_flag("--wait-banner", run.wait_banner, "send the job only after the firmware's first output line");
    run_cmd->add_option("--family", run.family,
                        "grbl | marlin | teacup | generic: the firmware's protocol on the --host port (default: the board's)");
    run_cmd->add_option("--line-timeout", run.line_timeout,
                        "a line unanswered this long with no output at all is a timeout (default: the board's, else the family's: marlin 5s, teacup 2.5s, grbl and generic 2s; never under 2.5 times the keep-alive period seen)");
    run_cmd->add_option("--realtime", run.realtime,
                        "TIME=BYTES sent at that simulated time outside the line stream, e.g. 2s=! 4s=~ (grbl "
                        "feed hold/resume), 1s=^X, 3s=0x85 (repeatable; needs --gcode)");
    run_cmd->add_option("--settle", run.settle, "motion has stopped after no STEP edge for this long (default 50ms)");
    run_cmd->add_option("--report", run.report, "write an HTML report of the run (with --board)");
    run_cmd->add_flag("--until-sleep", run.until_sleep, "stop when the firmware first executes SLEEP (bounded by --for)");
    run_cmd->add_option("--uart-in", run.uart_in,
                        "FILE or PORT=FILE: raw bytes to send to a serial port (the board's first, or USART0; repeatable)");
    run_cmd->add_option("--uart-out", run.uart_out,
                        "FILE or PORT=FILE: write what the firmware sent on a serial port (repeatable)");
    run_cmd->add_flag("-q,--quiet", run.quiet, "no progress bar");
    run_cmd->add_flag("--no-idle-skip", run.no_idle_skip,
                      "run every pass of the firmware's idle loops instead of jumping over them (same results, slower)");
    run_cmd->add_flag("--no-periodic-waves", run.no_periodic_waves,
                      "deliver every edge of a timer PWM through its net even when nothing records it "
                      "(heaters follow each edge instead of the mean power; slower)");

    CheckArgs check;
    CLI::App* check_cmd = app.add_subcommand("check", "run scenario files: stimulus, expectations, golden comparison");
    check_cmd->add_option("scenarios", check.scenarios, "scenario files (tests/scenarios/*.yaml)")->required();
    check_cmd->add_option("--junit", check.junit, "write JUnit XML for CI");
    check_cmd->add_option("--report-dir", check.report_dir, "write an HTML report per scenario here");
    check_cmd->add_option("--vcd-dir", check.vcd_dir,
                          "write each scenario's waveforms here: <name>.vcd (sigrok-readable) and <name>.gtkw");
    check_cmd->add_option("--firmware-dir", check.firmware_dir, "where bare firmware names resolve (default: beside avrbench)");
    CheckArgs golden;
    CLI::App* golden_cmd = app.add_subcommand("golden", "manage golden timelines");
    golden_cmd->require_subcommand(1);
    CLI::App* update_cmd = golden_cmd->add_subcommand("update", "rerun scenarios and rewrite their golden timelines (never done implicitly)");
    update_cmd->add_option("scenarios", golden.scenarios, "scenario files")->required();
    update_cmd->add_option("--firmware-dir", golden.firmware_dir, "where bare firmware names resolve");
    update_cmd->add_flag("--force", golden.force, "write the golden even when the run fails its steps or expectations");

    CLI::App* boards_cmd = app.add_subcommand("boards", "list the standard boards (names for --board and scenarios) with their descriptions");

    CLI::App* findings_cmd = app.add_subcommand("findings", "list the finding kinds with their severity and meaning");

    CamArgs cam;
    CLI::App* cam_cmd = app.add_subcommand("cam", "seed 002's CAM: a DXF drawing (lines, arcs, circles) to G-code");
    cam_cmd->add_option("dxf", cam.dxf, "the drawing, machine millimetres from home")->required();
    cam_cmd->add_option("-o,--output", cam.out, "the .nc file to write (default: beside the DXF)");
    cam_cmd->add_option("--tolerance", cam.tolerance, "endpoints closer than this are one point (default 0.01mm)");
    cam_cmd->add_option("--feed", cam.feed, "drawing feed in mm/min (default 600)");

    FuzzArgs fuzz;
    CLI::App* fuzz_cmd = app.add_subcommand("fuzz", "coverage-guided G-code fuzzing of a firmware on a board (libFuzzer or AFL++; docs/FUZZING.md)");
    fuzz_cmd->add_option("--elf", fuzz.elf, "the firmware")->required();
    fuzz_cmd->add_option("--board", fuzz.board, "board file or standard board name; --elf runs on its serial port's MCU")->required();
    fuzz_cmd->add_option("--for", fuzz.duration, "wall-clock time of the campaign (default 60s; with --runs its upper bound)");
    fuzz_cmd->add_option("--runs", fuzz.runs,
                         "executions of the campaign: with one job and a --seed, the same inputs on any machine "
                         "(libFuzzer -runs, AFL++ -E)");
    fuzz_cmd->add_option("--bound", fuzz.bound, "simulated time one input may take (default 5s; above the port's line timeout)");
    fuzz_cmd->add_option("--out", fuzz.out, "corpus, reproducers, runs and the libFuzzer log (default fuzz-out)");
    fuzz_cmd->add_option("--family", fuzz.family, "the host's firmware family: grbl, marlin, teacup, generic (default: the board's)");
    fuzz_cmd->add_flag("--hang", fuzz.hang, "a line still unanswered when --bound ends is a finding, keep-alives or not");
    fuzz_cmd->add_flag("--raw", fuzz.raw, "send the input's bytes to the port as they are (binary protocols such as seed 002's records)");
    fuzz_cmd->add_option("--boot", fuzz.boot, "with --raw: simulated time the firmware boots before the first input (default 0.2s)");
    fuzz_cmd->add_option("--firmware", fuzz.firmware, "MCU=ELF for a multi-MCU board's other MCUs (repeatable; as run's)");
    fuzz_cmd->add_option("--corpus", fuzz.corpus, "a directory of seed inputs (your jobs' lines) added to the family's seed lines");
    fuzz_cmd->add_option("--engine", fuzz.engine, "libfuzzer (default) or afl (Debian's afl++: one main and --jobs - 1 secondary instances)")
        ->check(CLI::IsMember({"libfuzzer", "afl"}));
    fuzz_cmd->add_option("--jobs", fuzz.jobs, "parallel jobs: libFuzzer's fork jobs or AFL++ instances (default 1)");
    fuzz_cmd->add_option("--seed", fuzz.seed, "the engine's random seed (default 1)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "avrbench: usage error: %s (see avrbench --help)\n", escaped(e.what()).c_str());
        return kExitBadInput;
    }
    install_user_stop_handlers();
    int code = 0;
    try {
        reject_empty_values(app);
        if (run_cmd->parsed()) code = run_command(run);
        if (check_cmd->parsed()) code = check_command(check, false);
        if (update_cmd->parsed()) code = check_command(golden, true);
        if (cam_cmd->parsed()) code = cam_command(cam);
        if (boards_cmd->parsed()) code = boards_command();
        if (findings_cmd->parsed()) code = findings_command();
        if (fuzz_cmd->parsed()) code = fuzz_command(fuzz);
    } catch (const BadInput& e) {
        // Escaped: a message that quotes a user's string stays one line and
        // never drives the terminal (core/InputFile.hpp).
        std::fflush(stdout);
        std::fprintf(stderr, "avrbench: error: %s\n", escaped(e.what()).c_str());
        code = kExitBadInput;
    } catch (const std::exception& e) {
        std::fflush(stdout);
        std::fprintf(stderr, "avrbench: internal error: %s\n", escaped(e.what()).c_str());
        code = kExitInternal;
    }
    // A summary that could not be written is a failed run (a full disk, a closed pipe).
    if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
        std::fprintf(stderr, "avrbench: error: cannot write to standard output\n");
        return kExitBadInput;
    }
    return code;
}
