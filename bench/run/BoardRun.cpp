#include "run/BoardRun.hpp"

#include "core/TextPattern.hpp"

#include <cctype>
#include <chrono>
#include <cstdio>
#include <sstream>
#include <thread>

#include "core/Errors.hpp"
#include "core/Format.hpp"
#include "core/InputFile.hpp"
#include "mcu/TimingProfile.hpp"
#include "periph/twi/Twi.hpp"
#include "core/Units.hpp"
#include "stimulus/PtyBridge.hpp"
#include "stimulus/RecordHost.hpp"
#include "trace/HtmlReport.hpp"
#include "trace/WaveformFiles.hpp"
#include "run/LiveStatus.hpp"

namespace avrbench {
namespace {

// The last `max_lines` lines of a port's text, indented, escaped.
void append_text_tail(std::vector<std::string>& out, const std::string& text, std::size_t max_lines) {
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
    for (std::size_t i = from; i < lines.size(); ++i) out.push_back("    " + hex_escaped(lines[i]));
}

// A port's bytes, when they are a binary protocol (Klipper's frames, seed
// 002's records: more than one byte in ten a control byte other than line
// ends and tabs), as their count and the last 48 in hex, each frame ending
// at Klipper's sync byte 0x7E on a line of its own: escaped "lines" of
// binary say nothing.
bool append_binary_tail(std::vector<std::string>& out, const std::string& bytes) {
    std::size_t control = 0;
    for (const char c : bytes) {
        const auto b = static_cast<unsigned char>(c);
        if ((b < 0x20 && b != '\n' && b != '\r' && b != '\t') || b >= 0x7F) ++control;
    }
    if (bytes.empty() || control * 10 <= bytes.size()) return false;
    const std::size_t from = bytes.size() > 48 ? bytes.size() - 48 : 0;
    out.push_back(format_text("    (binary: %zu bytes; the last %zu in hex)", bytes.size(), bytes.size() - from));
    std::string line = "    ";
    for (std::size_t i = from; i < bytes.size(); ++i) {
        const auto b = static_cast<unsigned char>(bytes[i]);
        line += format_text(line.size() > 4 ? " %02x" : "%02x", b);
        if (b == 0x7E) {
            out.push_back(line);
            line = "    ";
        }
    }
    if (line.size() > 4) out.push_back(line);
    return true;
}

// PB5, PORTB or all name pins of every MCU; MCU.PB5, MCU.PORTB or MCU.all
// those of one MCU; PART.SIGNAL a part's signal (hotend.block_degC) and a
// net's or label's name its MCU pin, as the summary and the VCD name them.
// `parts_traced`: every part signal is recorded already (the defaults).
void trace_board_pins(Bench& bench, const std::string& spec, const char* option, bool parts_traced) {
    if (spec.empty()) return;
    Recorder& recorder = bench.recorder();
    Board& board = bench.board();
    std::string every_mcu;
    std::map<std::string, std::string> per_mcu;
    std::map<std::string, std::vector<std::string>> per_part;
    std::stringstream items(spec);
    std::string item;
    while (std::getline(items, item, ',')) {
        const auto dot = item.find('.');
        if (dot == std::string::npos) {
            // A net or label by its board-file name: its MCU pin, shown under that name too.
            const Endpoint* endpoint = nullptr;
            std::string scope;
            for (const auto& net : board.spec().nets) {
                if (net.name != item) continue;
                for (const auto& e : net.endpoints) {
                    if (board.spec().find_mcu(e.owner) != nullptr) {
                        endpoint = &e;
                        break;
                    }
                }
                scope = "nets";
            }
            for (const auto& label : board.spec().labels) {
                if (label.name == item) endpoint = &label.endpoint, scope = "labels";
            }
            if (endpoint != nullptr) {
                Mcu& m = board.mcu(endpoint->owner);
                bench.timeline().add_alias(recorder.trace_pin(m, m.pin(endpoint->pin)), scope, item);
                continue;
            }
            every_mcu += item + ",";
            continue;
        }
        const std::string owner = item.substr(0, dot);
        if (board.spec().find_mcu(owner) != nullptr) {
            per_mcu[owner] += item.substr(dot + 1) + ",";
        } else if (board.spec().find_part(owner) != nullptr) {
            per_part[owner].push_back(item.substr(dot + 1));
        } else {
            throw BadInput(std::string(option) + ": '" + item + "': the board has no MCU or part '" + owner + "'");
        }
    }
    for (Mcu* m : board.mcus()) {
        if (!every_mcu.empty()) trace_pins_option(recorder, *m, every_mcu, option);
        if (const auto it = per_mcu.find(m->name()); it != per_mcu.end()) trace_pins_option(recorder, *m, it->second, option);
    }
    for (const auto& [part, signals] : per_part) {
        try {
            if (parts_traced) {
                Part& p = board.part(part);
                for (const auto& name : signals) {
                    if (bench.timeline().find(part, name) < 0) recorder.trace_part(p, {name});  // checks the name
                }
            } else {
                recorder.trace_part(board.part(part), signals);
            }
        } catch (const BadInput& e) {
            throw BadInput(std::string(option) + ": " + e.what());
        }
    }
}

}  // namespace

void trace_pins_option(Recorder& recorder, Mcu& mcu, const std::string& spec, const char* option) {
    try {
        recorder.trace_pins(mcu, spec);
    } catch (const BadInput& e) {
        throw BadInput(std::string(option) + ": " + e.what());
    }
}

BoardRun::BoardRun(BoardRunOptions options) : options_(std::move(options)) {
    BoardSpec spec = load_board_file(options_.board);
    // The first MCU's ELF may come as `elf` (the CLI's positional argument) or in `firmware`.
    if (!options_.elf.empty()) options_.firmware[spec.mcus.front().name] = options_.elf;
    check_files(spec);
    if (!options_.read_uart_input) {
        options_.read_uart_input = [](const std::string& path) {
            return read_input_file(path, "--uart-in", kMaxUartInputBytes);
        };
    }
    std::vector<std::pair<std::string, std::string>> uart_in_bytes;  // port -> bytes
    for (const auto& pb : options_.uart_in) uart_in_bytes.emplace_back(pb.port, options_.read_uart_input(pb.path));
    if (options_.gcode) check_input_file(options_.gcode->path, "--gcode", kMaxGcodeFileBytes);

    bench_ = std::make_unique<Bench>(std::move(spec), options_.firmware);
    Board& board = bench_->board();
    for (Mcu* m : board.mcus()) {
        m->set_skip_idle_loops(options_.skip_idle_loops);
        m->set_predecoded_core(options_.predecoded_core);
        m->set_translate_blocks(options_.translate_blocks);
    }
    if (!options_.profile.empty()) {
        for (Mcu* m : board.mcus()) m->enable_profile();
    }
    if (!options_.periodic_waves) board.set_periodic_waves(false);
    const bool job = options_.gcode || static_cast<bool>(options_.records);
    if (bench_->serial_ports().empty() && (!options_.uart_in.empty() || !options_.uart_out.empty() || job)) {
        throw BadInput(options_.board +
                       ": the board has no serial port, no serial_host part (needed by --gcode, --dxf, --uart-in, --uart-out)");
    }
    // Resolve every named port now, so a typo fails before the run.
    for (const auto& pb : options_.uart_in) bench_->serial_port(pb.port);
    for (const auto& pb : options_.uart_out) bench_->serial_port(pb.port);
    if (!options_.job_port.empty()) bench_->serial_port(options_.job_port);
    if (options_.gcode) {
        start_gcode_job();
    }
    if (options_.records) {
        if (options_.gcode) throw BadInput("--dxf and --gcode: give one job");
        start_record_job();
    }
    for (const auto& [port, bytes] : uart_in_bytes) bench_->serial(port).send(bytes);
    if (options_.pty) open_pty();
    count_i2c();
    if (!options_.vcd.empty() || !options_.report.empty()) trace();
}

BoardRun::~BoardRun() = default;

void BoardRun::check_files(const BoardSpec& spec) {
    RunFiles files;
    if (!options_.elf.empty()) files.input(options_.elf, "the firmware ELF");
    files.input(spec.path, "an input of the board");
    for (const auto& [mcu, elf] : options_.firmware) files.input(elf, "an input of the board");
    for (const auto& m : spec.mcus) files.input(m.bootloader, "an input of the board");
    if (options_.gcode) files.input(options_.gcode->path, "--gcode");
    for (const auto& pb : options_.uart_in) {
        if (pb.path != "-") files.input(pb.path, "--uart-in");
    }
    files.add(options_.more_files);
    if (!options_.vcd.empty()) {
        files.output(options_.vcd, "--vcd");
        files.output(with_extension(options_.vcd, ".gtkw"), "--vcd's gtkwave save file");
    }
    if (!options_.report.empty()) files.output(options_.report, "--report");
    if (!options_.profile.empty()) files.output(options_.profile, "--profile");
    for (const auto& pb : options_.uart_out) files.output(pb.path, "--uart-out");
    files.check();
}

void BoardRun::start_gcode_job() {
    const BoardRunOptions::GcodeJob& job = *options_.gcode;
    const SerialPort& decl = bench_->serial_port(options_.job_port);
    for (const auto& pb : options_.uart_in) {
        if (bench_->serial_port(pb.port).name == decl.name) {
            throw BadInput("--uart-in: port " + decl.name + " already streams --gcode; give another port (PORT=FILE)");
        }
    }
    UartHostOptions o = default_host_options(decl);
    if (!job.flow.empty()) o.flow = parse_flow_control(job.flow, "--flow");
    if (!job.family.empty()) o.family = parse_firmware_family(job.family, "--family");
    for (const std::string& p : job.error_patterns) {
        (void)TextPattern(p, "--error-pattern");
        o.error_patterns.push_back(p);
    }
    if (!job.line_timeout.empty()) {
        o.line_timeout_s = seconds_from_ps(parse_duration_ps(job.line_timeout, "--line-timeout"));
        if (!(o.line_timeout_s > 0)) throw BadInput("--line-timeout: must be longer than 0");
    }
    if (job.wait_banner) o.startup = Startup::WaitForBanner;
    if (job.generic_boot_s) start_generic_after_boot(o, *job.generic_boot_s);
    host_ = &bench_->host(decl.name, o);
    if (job.raw_bytes) {
        host_->add_lines(read_input_file(job.path, "--gcode", kMaxGcodeFileBytes));
    } else {
        host_->load_file(job.path);
    }
    for (const auto& [at_ps, bytes] : job.realtime) {
        host_->send_bytes_at(bytes, decl.mcu->cycles_from_seconds(seconds_from_ps(at_ps)));
    }
}

void BoardRun::start_record_job() {
    const BoardRunOptions::RecordJob job = options_.records();
    plot_source_ = job.source;
    plot_variant_ = job.variant;
    const SerialPort& port = bench_->serial_port(options_.job_port);
    plot_ = std::make_unique<RecordHost>(*port.mcu, port.link(), job.messages,
                                         RecordHost::Options{}, job.busy_seconds);
    plot_->start();
    if (!job.gcode.empty()) {
        bench_->command_program(job.gcode, job.source + "'s G-code");
        bench_->judge_job_by([this] { return plot_->finished(); });
    }
}

void BoardRun::open_pty() {
    const BoardRunOptions::Pty& pty = *options_.pty;
    const SerialPort& decl = bench_->serial_port(pty.port);
    if ((options_.gcode || plot_) && bench_->serial_port(options_.job_port).name == decl.name) {
        throw BadInput("--pty: port " + decl.name + " already carries the job");
    }
    pty_ = std::make_unique<PtyBridge>(bench_->serial(decl.name), pty.link);
    pty_mcu_ = decl.mcu;
    // At once, so a host can connect while the run goes on.
    if (options_.on_announce) {
        options_.on_announce("avrbench run: serial " + decl.name + " on " + pty_->path() + (pty.link.empty() ? "" : " = ") +
                             pty.link);
    }
}

void BoardRun::count_i2c() {
    Board& board = bench_->board();
    for (Mcu* m : board.mcus()) {
        Twi* twi = m->twi();
        if (twi == nullptr) continue;
        for (const auto& bus : board.twi_buses()) {
            if (&twi->bus() != bus.get() || bus->members().size() < 2) continue;
            auto count = std::make_shared<I2cCount>();
            i2c_[m->name()] = count;
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
}

void BoardRun::trace() {
    const bool defaults = options_.trace_only.empty();
    if (defaults) bench_->trace_board();
    trace_board_pins(*bench_, defaults ? options_.trace : options_.trace_only, defaults ? "--trace" : "--trace-only", defaults);
}

void BoardRun::after_slice(std::chrono::steady_clock::time_point wall_start) {
    Bench& bench = *bench_;
    if (pty_) {
        if (pty_->host_opened() && options_.pty->reset_on_open) {
            // What an Arduino's DTR capacitor does when the host opens the port.
            pty_mcu_->reset_external();
            ++resets_on_open_;
        }
        pty_->pump();
        if (options_.pty->realtime_pace) {
            // Simulated time no further than wall time (the host's timeouts are in seconds).
            const auto due = wall_start + std::chrono::nanoseconds(bench.now_ps() / 1000);
            std::this_thread::sleep_until(due);
        }
    }
    drain_(bench.now_ps());
    const bool asked = options_.status_now != nullptr && options_.status_now->exchange(false);
    if (asked || (options_.status_every_ps > 0 && bench.now_ps() >= next_status_ps_)) {
        report_status(wall_start);
        while (options_.status_every_ps > 0 && next_status_ps_ <= bench.now_ps()) next_status_ps_ += options_.status_every_ps;
    }
    if (options_.on_progress) {
        options_.on_progress(static_cast<double>(bench.now_ps()) / static_cast<double>(options_.duration_ps),
                             bench.now_seconds());
    }
}

void BoardRun::report_status(std::chrono::steady_clock::time_point wall_start) {
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    const LiveStatus status = live_status(*bench_, host_, wall_s);
    if (options_.on_status) options_.on_status(status.line);
    // Written to a temporary file and renamed: a reader never sees half a status.
    if (!options_.status_file.empty()) write_output_file(options_.status_file, status.json, "--status-file");
}

IdleResult BoardRun::run() {
    Bench& bench = *bench_;
    std::vector<std::string> mcu_scopes;
    for (Mcu* m : bench.board().mcus()) mcu_scopes.push_back(m->name());
    // The VCD is streamed; a report keeps in memory only the signals it reads.
    WaveformFiles waveforms(bench.timeline(), options_.vcd, true, options_.vcd_layout, mcu_scopes);
    waveforms.start();
    std::vector<TimelineEvent> discarded;
    if (!options_.report.empty()) bench.timeline().keep_when_taken(bench.report_signal_mask());
    if (!options_.vcd.empty()) {
        drain_ = [&waveforms](Picoseconds now_ps) { waveforms.drain(now_ps); };
    } else if (!options_.report.empty()) {
        drain_ = [&bench, &discarded](Picoseconds) { bench.timeline().take_events_into(discarded); };
    } else {
        drain_ = [](Picoseconds) {};
    }
    const auto wall_start = std::chrono::steady_clock::now();
    Bench::RunSlices how;
    how.until_idle = host_ != nullptr;
    if (plot_) how.stop_when = [this] { return plot_->failed(); };
    how.settle_ps = options_.settle_ps;
    // A host on a pty at real time waits for each answer: 1 ms slices keep
    // the round trip near the UART's own (a 128-byte page at 115200 baud is
    // 11 ms; with 10 ms slices avrdude took 9.4 s to write grbl instead of ~5).
    if (pty_ && options_.pty->realtime_pace) how.slice_ps = kPsPerMs;
    how.after_slice = [this, wall_start] { after_slice(wall_start); };
    outcome_ = bench.run_to_ps(options_.duration_ps, how);
    drain_ = nullptr;
    wall_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

    if (bench.timeline().overflowed()) throw BadInput(bench.timeline().overflow_message());
    gtkw_path_ = waveforms.finish(bench.mcu().cycle(), bench.mcu().frequency_hz());
    for (const auto& pb : options_.uart_out) {
        write_output_file(pb.path, bench.serial(pb.port).transmitted_text(), "--uart-out");
    }
    findings_ = bench.findings();
    if (!options_.profile.empty()) {
        std::string json = "{\"mcus\": [";
        for (Mcu* m : bench.board().mcus()) json += std::string(json.back() == '[' ? "" : ", ") + m->profile()->json();
        write_output_file(options_.profile, json + "]}\n", "--profile");
    }
    if (!options_.report.empty()) {
        write_html_report(bench.make_report(std::string(bench.mcu().elf().path()) + " on " + bench.board().spec().name),
                          options_.report);
    }
    return outcome_;
}

RunVerdict BoardRun::verdict(bool strict) const {
    using O = RunVerdict::Outcome;
    for (const auto& f : findings_) {
        if (f.kind.severity() == Severity::Error || (strict && f.kind != UartHost::kHostProtocol)) return {O::Finding, ""};
    }
    if (plot_ && plot_->failed()) return {O::Timeout, "timeout: " + plot_->failure()};
    if (outcome_ == IdleResult::Interrupted) {
        return {O::Interrupted,
                format_text("interrupted at %.6f s simulated; what was recorded is written", bench_->now_seconds())};
    }
    if (host_ != nullptr && outcome_ == IdleResult::HostFailed) {
        // A host that got no answer is a timeout; error/ALARM/!! are findings.
        bool timed_out = false;
        for (const auto& e : host_->events()) {
            timed_out = timed_out || e.kind == HostEventKind::Timeout || e.kind == HostEventKind::BannerTimeout;
        }
        return {timed_out ? O::Timeout : O::Finding, host_->failure_message()};
    }
    if (host_ != nullptr && outcome_ == IdleResult::TimeLimit) {
        std::string message = format_text("timeout: the job was not finished within %g s (%zu of %zu lines acknowledged)",
                                          seconds_from_ps(options_.duration_ps), host_->lines_acknowledged(),
                                          host_->lines().size());
        const auto& going = bench_->left_going();
        if (!going.empty()) message += "; still going: " + going.front();
        if (going.size() > 1) message += format_text(" (and %zu more, in the summary)", going.size() - 1);
        return {O::Timeout, message};
    }
    if (strict) {
        for (const auto& f : findings_) {
            if (f.kind == UartHost::kHostProtocol) return {O::Finding, ""};
        }
    }
    return {O::Ok, ""};
}

std::vector<std::string> BoardRun::summary() const {
    std::vector<std::string> out;
    const Bench& bench = *bench_;
    Board& board = bench_->board();
    const double simulated_s = bench.now_seconds();
    out.push_back(format_text("avrbench run: board %s (%s)", board.spec().name.c_str(), options_.board.c_str()));
    for (Mcu* m : board.mcus()) {
        out.push_back(format_text("  mcu        %s: %s at %.6g MHz, firmware %s%s", m->name().c_str(), m->mcu_type().c_str(),
                             m->frequency_hz() / 1e6, m->elf().path().c_str(), m->halted() ? " (halted)" : ""));
    }
    for (Mcu* m : board.mcus()) {
        if (!m->boot()) continue;
        out.push_back(format_text(
            "  boot       %s: %s at 0x%05X (%u bytes), started the application %u time%s; the application section %s",
            m->name().c_str(), m->bootloader_path().c_str(), m->boot()->start_bytes, m->boot()->size_bytes,
            m->application_starts(), m->application_starts() == 1 ? "" : "s",
            m->elf_matches_flash() ? "holds the ELF" : "now differs from the ELF (rewritten by the boot loader)"));
    }
    out.push_back(format_text("  simulated  %.6f s", simulated_s));
    out.push_back(format_text("  wall       %.3f s, real-time factor %.1fx", wall_s_, wall_s_ > 0 ? simulated_s / wall_s_ : 0.0));
    for (Mcu* m : board.mcus()) {
        if (m->idle_jumps() == 0) continue;
        out.push_back(format_text("  idle skip  %s%llu jumps over %.6f s of idle-loop passes",
                             board.mcus().size() > 1 ? (m->name() + ": ").c_str() : "",
                             static_cast<unsigned long long>(m->idle_jumps()),
                             static_cast<double>(m->idle_cycles_skipped()) / m->frequency_hz()));
    }
    if (pty_) {
        std::string line = format_text("  pty        %s: %llu bytes to the firmware, %llu from it%s", pty_->path().c_str(),
                                  static_cast<unsigned long long>(pty_->bytes_to_firmware()),
                                  static_cast<unsigned long long>(pty_->bytes_to_host()),
                                  pty_->bytes_dropped() != 0 ? " (the host did not read them all)" : "");
        if (options_.pty->reset_on_open) line += format_text(", %u resets on open", resets_on_open_);
        out.push_back(line);
    }
    if (plot_) {
        out.push_back(format_text("  plot       %s: %zu of %zu records acknowledged (%s)%s", plot_source_.c_str(),
                             plot_->acknowledged(), plot_->messages(), plot_variant_.c_str(),
                             plot_->failed() ? ", failed" : ""));
    }
    if (host_ != nullptr) {
        out.push_back(format_text("  job        %s: %zu of %zu lines acknowledged (%zu ok, %zu error), %s",
                             options_.gcode->path.c_str(), host_->lines_acknowledged(), host_->lines().size(),
                             host_->oks(), host_->errors(), to_string(outcome_)));
        // Why a job that did not end idle had not: what the firmware was still doing.
        if (outcome_ != IdleResult::Idle) {
            for (const std::string& why : bench_->left_going()) out.push_back("  going      " + why);
        }
    }
    for (const auto& [mcu, count] : i2c_) {
        if (count->transfers == 0) continue;  // a master that never spoke is no master
        out.push_back(format_text("  i2c        %s as master: %llu transfers, %llu data bytes, %llu NACKed by a slave",
                             mcu.c_str(), static_cast<unsigned long long>(count->transfers),
                             static_cast<unsigned long long>(count->bytes), static_cast<unsigned long long>(count->nacks)));
    }
    for (Part* part : board.parts()) {
        if (const std::string line = part->summary(); !line.empty()) out.push_back("  " + line);
    }
    for (Mcu* m : board.mcus()) {
        if (m->profile() == nullptr) continue;
        for (const std::string& line : m->profile()->summary_lines()) out.push_back("  profile    " + m->name() + ": " + line);
    }
    for (Mcu* m : board.mcus()) {
        for (const std::string& text : m->requested_reset_lines()) {
            out.push_back("  reset      " + (board.mcus().size() > 1 ? m->name() + ": " : std::string()) + text);
        }
    }
    out.push_back(format_text("  findings   %zu", findings_.size()));
    for (const auto& line : summarize_findings(findings_)) out.push_back("    " + line);
    if (host_ != nullptr) {
        out.push_back("  transcript (last lines):");
        append_text_tail(out, host_->tail(10), 10);
    }
    for (const auto& decl : bench_->serial_ports()) {
        if ((host_ != nullptr || plot_) && bench_->serial_port(options_.job_port).name == decl.name) continue;
        const SerialLink& u = decl.link();
        const std::string bytes = u.transmitted_text();
        std::vector<std::string> tail;
        const bool binary = append_binary_tail(tail, bytes);
        if (!binary) append_text_tail(tail, bytes, 10);
        out.push_back(format_text("  serial %-4s %zu bytes from firmware, %llu bytes to firmware%s", decl.name.c_str(),
                                  u.transmitted().size(), static_cast<unsigned long long>(u.bytes_delivered()),
                                  u.transmitted().empty() ? "" : binary ? ":" : "; last lines:"));
        out.insert(out.end(), tail.begin(), tail.end());
    }
    if (!options_.vcd.empty()) {
        const Timeline& timeline = bench_->timeline();
        out.push_back(format_text("  vcd        %s (%zu signals, %llu events), gtkwave save file %s", options_.vcd.c_str(),
                             timeline.signals().size(), static_cast<unsigned long long>(timeline.recorded_count()),
                             gtkw_path_.c_str()));
    }
    if (!options_.report.empty()) out.push_back("  report     " + options_.report);
    return out;
}

}  // namespace avrbench
