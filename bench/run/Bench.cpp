#include "run/Bench.hpp"

#include "periph/ports/McuPins.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <deque>
#include <cstdlib>
#include <map>
#include <optional>
#include <set>

#include "mcu/TimingProfile.hpp"
#include "core/Units.hpp"
#include "core/UserStop.hpp"
#include "parts/AcceptedMoves.hpp"
#include "stimulus/CommandedTarget.hpp"
#include "run/CardPrint.hpp"
#include "run/CommandedPath.hpp"
#include "run/HeatTargets.hpp"

namespace avrbench {

const char* to_string(IdleResult result) {
    switch (result) {
        case IdleResult::Idle: return "idle";
        case IdleResult::TimeLimit: return "time-limit";
        case IdleResult::Halted: return "halted";
        case IdleResult::HostFailed: return "host-failed";
        case IdleResult::Interrupted: return "interrupted";
        case IdleResult::RecorderFull: return "recorder-full";
    }
    return "?";
}

namespace {

// Step intervals longer than this are a machine at rest between moves, not
// a slow move (assumed: 4 steps/s, slower than the slowest homing approach
// the motion oracle's rest_time allows for, 5 steps/s).
constexpr Picoseconds kLongestStepIntervalCounted = kPsPerMs * 250;

}  // namespace

Bench::Bench(const std::string& board_file, const std::string& elf) {
    BoardSpec spec = load_board_file(board_file);
    const std::string first = spec.mcus.front().name;
    board_ = std::make_unique<Board>(std::move(spec), std::map<std::string, std::string>{{first, elf}});
    watch_motion();
}

Bench::Bench(const std::string& board_file, const std::map<std::string, std::string>& firmware)
    : Bench(load_board_file(board_file), firmware) {}

Bench::Bench(BoardSpec spec, const std::map<std::string, std::string>& firmware)
    : board_(std::make_unique<Board>(std::move(spec), firmware)) {
    watch_motion();
}

Bench::~Bench() = default;

void Bench::watch_motion() {
    // The board's serial ports: its parts that hosts attach to (the links
    // record what the firmware sends from power-on).
    for (Part* part : board_->parts()) {
        if (auto* connector = dynamic_cast<HostConnector*>(part)) {
            const PartDecl* decl = board_->spec().find_part(part->name());
            serial_ports_.push_back({part->name(), &part->clock(), connector, decl != nullptr ? decl->location : ""});
        }
    }
    for (Part* part : board_->parts()) {
        part->on_activity([this, part] {
            const Picoseconds now = ps_at_cycle(part->clock(), part->clock().cycle());
            last_step_ps_ = now;
            auto [it, first] = last_step_by_part_ps_.try_emplace(part, now);
            if (!first) {
                const Picoseconds interval = now - std::min(now, it->second);
                if (interval <= kLongestStepIntervalCounted) longest_step_interval_ps_ = std::max(longest_step_interval_ps_, interval);
                it->second = now;
            }
        });
    }
    heat_ = std::make_unique<HeatTargets>(*board_);
    for (const SerialPort& port : serial_ports_) watch_port(port);
}

// Lines written by hand on `port`: each is taken when its '\n' reaches the
// firmware, answered by the first line the firmware completes after that.
void Bench::watch_port(const SerialPort& port) {
    HandWritten& hand = hand_[port.name];
    port.link().on_deliver([&hand](Cycle cycle, std::uint8_t) {
        ++hand.delivered;
        while (!hand.untaken.empty() && hand.untaken.front().first <= hand.delivered) {
            hand.unanswered.emplace_back(cycle, std::move(hand.untaken.front().second));
            hand.untaken.pop_front();
        }
    });
    const FirmwareFamily family = parse_firmware_family(port.protocol().family, port.location);
    port.link().on_transmit([&hand, family](Cycle cycle, std::uint8_t byte) {
        if (byte != '\n' && byte != '\r') {
            if (!hand.unanswered.empty() && hand.partial.size() < 256) hand.partial.push_back(static_cast<char>(byte));
            return;
        }
        std::string line = std::move(hand.partial);
        hand.partial.clear();
        if (line.empty() || hand.unanswered.empty() || cycle <= hand.unanswered.front().first) return;
        // A known family answers with ok or an error; a generic firmware's
        // every line answers.
        const AnswerKind kind = classify_answer(family, line);
        const bool answers = family == FirmwareFamily::Generic || kind == AnswerKind::Ok || kind == AnswerKind::Error ||
                             kind == AnswerKind::Alarm || kind == AnswerKind::Fatal;
        if (answers) hand.unanswered.pop_front();
    });
}

void Bench::write(const std::string& port, const std::string& bytes) {
    const SerialPort& p = serial_port(port);
    HandWritten& hand = hand_[p.name];
    // The byte numbers these will have on the link: after what it delivered
    // and what is queued before them.
    const std::uint64_t base = hand.delivered + p.link().pending_rx();
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        if (bytes[i] != '\n') continue;
        std::string text = bytes.substr(line_start, std::min<std::size_t>(i - line_start, 200));
        if (!text.empty() && text.back() == '\r') text.pop_back();
        hand.untaken.emplace_back(base + i + 1, std::move(text));
        line_start = i + 1;
    }
    hand.written_end = std::max(hand.written_end, base + bytes.size());
    p.link().send(bytes);
}

UartHostOptions default_host_options(const SerialPort& port) {
    const HostProtocol& p = port.protocol();
    UartHostOptions o;
    o.flow = parse_flow_control(p.flow, port.location);
    o.rx_buffer_bytes = p.rx_buffer_bytes;
    o.family = parse_firmware_family(p.family, port.location);
    o.line_timeout_s = p.line_timeout_s;
    if (!p.error_pattern.empty()) o.error_patterns.push_back(p.error_pattern);
    return o;
}

const SerialPort& Bench::serial_port(const std::string& port) const {
    if (serial_ports_.empty()) {
        throw BadInput(board_->spec().path + ": the board has no serial port (a serial_host part, docs/BOARDS.md)");
    }
    if (port.empty()) return serial_ports_.front();
    for (const auto& s : serial_ports_) {
        if (s.name == port) return s;
    }
    std::string list;
    for (const auto& s : serial_ports_) list += (list.empty() ? "" : ", ") + s.name;
    throw BadInput(board_->spec().path + ": no serial port '" + port + "' (ports: " + list + ")");
}

SerialLink& Bench::serial(const std::string& port) { return serial_port(port).link(); }

UartHost& Bench::host(const std::string& port, std::optional<UartHostOptions> options) {
    const SerialPort& serial = serial_port(port);
    auto& slot = hosts_[serial.name];
    if (!slot) {
        UartHostOptions o;
        if (options) {
            o = *options;
        } else {
            o = default_host_options(serial);
        }
        slot = std::make_unique<UartHost>(*serial.mcu, serial.link(), o);
        // A step anywhere on the board is the firmware at work on a waiting line.
        Mcu& host_mcu = *serial.mcu;
        slot->set_activity_probe([this, &host_mcu]() -> std::optional<Cycle> {
            if (!last_step_ps_) return std::nullopt;
            return cycle_at_ps(host_mcu, *last_step_ps_);
        });
        check_accepted_moves(*slot);
        // Heater targets from the lines the firmware took (not those it refused).
        Mcu& clock = *serial.mcu;
        slot->on_answer([this, &clock](const GcodeLine& line, std::size_t, bool refused) {
            if (refused) return;
            heat_->accepted(line.text, ps_at_cycle(clock, clock.cycle()), "line " + std::to_string(line.number) + " " + quoted_line(line.text));
        });
    }
    return *slot;
}

std::vector<CommandedMoves*> Bench::motion_judges() const {
    std::vector<CommandedMoves*> judges;
    for (Part* part : board_->parts()) {
        if (auto* judge = dynamic_cast<CommandedMoves*>(part)) judges.push_back(judge);
    }
    return judges;
}

void Bench::command_program(const std::string& gcode, const std::string& source) {
    std::vector<CommandedPath> paths;
    for (CommandedMoves* judge : motion_judges()) paths.emplace_back(*judge);
    if (paths.empty()) return;
    std::size_t number = 0;
    std::size_t begin = 0;
    while (begin < gcode.size()) {
        std::size_t end = gcode.find('\n', begin);
        if (end == std::string::npos) end = gcode.size();
        std::string line = gcode.substr(begin, end - begin);
        begin = end + 1;
        ++number;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        const std::string quoted = source + " line " + std::to_string(number) + " " + quoted_line(line);
        for (auto& path : paths) path.accept(line, quoted);
    }
}

namespace {

// A host's lines handed to one motion judge as they go out, so a firmware
// that answers once a move is done is followed while it moves. A line it
// refuses is taken back: its moves and those of the lines sent after it are
// retracted, the reading state from before it is put back and the later
// lines read again; where the judge cannot (the machine began one of those
// moves) or a G92 is among them, the judge stops.
struct SentLineFeed {
    SentLineFeed(CommandedMoves& j, FirmwareFamily family, std::vector<const StoredFiles*> card_slots)
        : judge(&j), path(j), grbl(family == FirmwareFamily::Grbl), cards(std::move(card_slots)) {
        const FamilyArcs arcs = family_arcs(family);
        path.set_arc_rule({arcs.tolerance_mm, arcs.segment_mm});
    }
    CommandedMoves* judge;
    CommandedPath path;
    bool grbl;
    std::vector<const StoredFiles*> cards;
    std::string selected_file;  // the last M23's
    bool selected_started = false;  // an M24 started it: another resumes it
    // grbl 1.1 picks its realtime commands out of the stream wherever they
    // are, in a line it then refuses too (serial.c's receive interrupt, the
    // CMD_ bytes of config.h): those that change how the machine moves are
    // the feed hold '!', the reset ^X, the safety door 0x84, the jog cancel
    // 0x85 and the feed and rapid overrides 0x90-0x97. The machine may then
    // stop or change speed anywhere, on the moves it is making too: judging
    // stops for good. '?', '~', the spindle and coolant overrides and any
    // other byte over 0x7F never reach the line grbl reads.
    static bool moves_differently(unsigned char b) {
        return b == '!' || b == 0x18 || b == 0x84 || b == 0x85 || (b >= 0x90 && b <= 0x97);
    }
    static bool holds_or_overrides(const std::string& text) {
        return std::any_of(text.begin(), text.end(), [](char c) { return moves_differently(static_cast<unsigned char>(c)); });
    }
    static std::string line_grbl_reads(const std::string& text) {
        std::string kept;
        for (const char c : text) {
            const auto b = static_cast<unsigned char>(c);
            if (b == '?' || b == '~' || b == '!' || b == 0x18 || b > 0x7F) continue;
            kept.push_back(c);
        }
        return kept;
    }
    static constexpr const char* kRealtimeWhy =
        "carries a grbl realtime command (a feed hold, reset or override: the machine may stop anywhere)";
    struct Unanswered {
        GcodeLine line;
        CommandedPath before;  // the reading state before the line
        std::size_t moves = 0;
        bool renamed = false;
        bool changed = false;     // it moved, renamed or changed a mode
        bool lost_frame = false;  // reading it stopped the judging
        bool lost_for_good = false;  // and no refusal can undo that (grbl realtime bytes)
    };
    std::deque<Unanswered> unanswered;

    void sent(const GcodeLine& line) {
        Unanswered u{line, path};
        const std::string quoted = "line " + std::to_string(line.number) + " " + quoted_line(line.text);
        if (grbl && holds_or_overrides(line.text)) {
            u.lost_for_good = true;
            path.stop_now(quoted, kRealtimeWhy);
        }
        if (const auto card = grbl ? std::nullopt : card_print_command(line.text)) {
            print_from_card(*card, quoted);
        } else {
            path.accept(grbl ? line_grbl_reads(line.text) : line.text, quoted);
        }
        u.moves = path.moves_told() - u.before.moves_told();
        u.renamed = path.renames_told() != u.before.renames_told();
        u.changed = u.moves != 0 || u.renamed || !path.same_state(u.before);
        u.lost_frame = path.lost() && !u.before.lost();
        unanswered.push_back(std::move(u));
    }
    // M23 selects the file; M24 starts it: its lines are what the firmware
    // is told next (a firmware reads the host's later lines while it prints,
    // so a job that also sends moves then is not judged in order).
    void print_from_card(const CardPrintCommand& card, const std::string& quoted) {
        if (card.kind == CardPrintCommand::Kind::Select) {
            selected_file = card.file;
            selected_started = false;
            return;
        }
        if (selected_file.empty()) return path.lose(quoted, "starts a card print with no file selected (M23)");
        if (selected_started) return;
        selected_started = true;
        std::string why;
        const auto program = card_file(cards, selected_file, why);
        if (!program) return path.lose(quoted, why);
        // Its lines as a firmware's reader takes them: comments and blank lines dropped.
        for (const GcodeLine& line : parse_gcode(*program, selected_file)) {
            if (path.lost()) break;
            path.accept(line.text, quoted + ": card file " + selected_file + " line " + std::to_string(line.number) + " " +
                                       quoted_line(line.text));
        }
    }
    // Bytes sent outside the lines, at a time (--realtime).
    void bytes_sent(const std::string& bytes) {
        if (grbl && holds_or_overrides(bytes)) path.stop_now("the bytes " + quoted_line(bytes) + " sent on their own", kRealtimeWhy);
    }
    void answered(const GcodeLine& line, bool refused) {
        while (!unanswered.empty() && unanswered.front().line.number < line.number) unanswered.pop_front();
        if (unanswered.empty() || unanswered.front().line.number != line.number) return;
        Unanswered refused_line = std::move(unanswered.front());
        unanswered.pop_front();
        if (!refused || !refused_line.changed) return;
        // A realtime command in it or after it stopped the judging for good.
        if (refused_line.lost_for_good ||
            std::any_of(unanswered.begin(), unanswered.end(), [](const Unanswered& u) { return u.lost_for_good; })) {
            return;
        }
        std::size_t moves = refused_line.moves;
        bool renamed = refused_line.renamed;
        bool stop_after = refused_line.lost_frame;
        for (const auto& later : unanswered) {
            moves += later.moves;
            renamed = renamed || later.renamed;
            stop_after = stop_after || later.lost_frame;
        }
        if (renamed || !judge->retract(moves, stop_after)) {
            // The lines sent after it were read in a frame the firmware never
            // took: take their moves back where the judge can, then stop.
            if (renamed) (void)judge->retract(moves, stop_after);
            path.lose("line " + std::to_string(line.number) + " " + quoted_line(line.text) + ", refused,");
            return;
        }
        // The line that stopped the judging (G5, a bare number) was refused:
        // the firmware's frame is what it was, and judging goes on with the
        // lines after it read again.
        if (refused_line.lost_frame && !judge->frame_restored()) {
            path.lose("line " + std::to_string(line.number) + " " + quoted_line(line.text) + ", refused,");
            return;
        }
        path = std::move(refused_line.before);
        std::deque<Unanswered> again = std::move(unanswered);
        unanswered.clear();
        for (const auto& later : again) sent(later.line);
    }
};

}  // namespace

void Bench::judge_job_by(const std::function<bool()>& all_answered) const {
    for (CommandedMoves* judge : motion_judges()) judge->job_answered_by(all_answered);
}

void Bench::follow_sent_lines(UartHost& host) {
    auto feeds = std::make_shared<std::vector<SentLineFeed>>();
    std::vector<const StoredFiles*> cards;
    for (Part* part : board_->parts()) {
        if (const auto* card = dynamic_cast<const StoredFiles*>(part)) cards.push_back(card);
    }
    for (CommandedMoves* judge : motion_judges()) feeds->emplace_back(*judge, host.options().family, cards);
    if (feeds->empty()) return;
    judge_job_by([&host] { return host.done(); });
    auto last_sent = std::make_shared<std::size_t>(0);
    host.on_line_sent([feeds, last_sent](const GcodeLine& line) {
        if (line.number <= *last_sent) return;  // a resend: read once
        *last_sent = line.number;
        for (auto& feed : *feeds) feed.sent(line);
    });
    // Refused: answered with an error, or with an error before its ok
    // (Marlin's "Error:" or "echo:Unknown command", Teacup's "E:").
    host.on_answer([feeds](const GcodeLine& line, std::size_t, bool refused) {
        for (auto& feed : *feeds) feed.answered(line, refused);
    });
    host.on_bytes_sent([feeds](const std::string& bytes) {
        for (auto& feed : *feeds) feed.bytes_sent(bytes);
    });
}

void Bench::check_accepted_moves(UartHost& host) {
    follow_sent_lines(host);
    std::vector<AcceptedMoves*> robots;
    for (Part* part : board_->parts()) {
        auto* checker = dynamic_cast<AcceptedMoves*>(part);
        if (checker != nullptr && checker->checks_move_commands()) robots.push_back(checker);
    }
    if (robots.empty()) return;
    // Each answer, in the order the lines went out (stimulus/UartHost on_answer).
    struct Seen {
        CommandedTarget target;
    };
    auto seen = std::make_shared<Seen>();
    host.on_answer([this, &host, robots, seen](const GcodeLine& line, std::size_t, bool refused) {
        if (refused) {
            // An error: the firmware did not take the line (its axes stay as
            // they were). A refused target no robot reaches either is a
            // right answer, not a finding (findings() leaves it out).
            CommandedTarget probe = seen->target;
            const auto target = probe.accept(line.text);
            if (!target) return;
            const Eigen::Vector3d t{(*target)[0], (*target)[1], (*target)[2]};
            for (AcceptedMoves* robot : robots) {
                if (robot->refusal_is_right(t)) right_refusals_.insert({&host, line.number});
            }
            return;
        }
        const auto target = seen->target.accept(line.text);
        if (!target) return;
        const std::string quoted = "line " + std::to_string(line.number) + " " + quoted_line(line.text);
        for (AcceptedMoves* robot : robots) {
            if (!robot->check_accepted_move(Eigen::Vector3d{(*target)[0], (*target)[1], (*target)[2]}, quoted)) {
                for (CommandedMoves* judge : motion_judges()) judge->judged_elsewhere(quoted);
            }
        }
    });
}

void Bench::trace_board() {
    if (traced_) return;
    traced_ = true;
    std::map<std::string, SignalId> traced_pins;  // "uno.PD2" -> its signal
    auto trace = [&](const Endpoint& e) -> std::optional<SignalId> {
        if (board_->spec().find_mcu(e.owner) == nullptr) return std::nullopt;
        auto it = traced_pins.find(e.text());
        if (it != traced_pins.end()) return it->second;
        const SignalId id = recorder_.trace_pin(board_->mcu(e.owner), board_->mcu(e.owner).pin(e.pin));
        traced_pins.emplace(e.text(), id);
        return id;
    };
    // Each net and label is also shown under its board-file name (a VCD
    // alias of the MCU pin that drives or reads it: no extra events).
    for (const auto& net : board_->spec().nets) {
        std::optional<SignalId> pin;
        for (const auto& e : net.endpoints) {
            const auto id = trace(e);
            if (!pin) pin = id;
        }
        if (pin) timeline_.add_alias(*pin, "nets", net.name);
    }
    for (const auto& label : board_->spec().labels) {
        if (const auto id = trace(label.endpoint)) timeline_.add_alias(*id, "labels", label.name);
    }
    for (const auto& s : serial_ports_) {
        Uart* usart = s.connector->usart();
        if (usart == nullptr) continue;  // a bit-level port: its pins are on nets, traced above
        Mcu& m = *s.mcu;
        recorder_.trace_uart_tx(m, *usart);
        recorder_.trace_uart_rx(m, *usart);
        // The port's lines too, under the port's name, where a logic
        // analyser (sigrok's UART decoder) reads them: serial.<port>_txd/_rxd.
        if (const auto pins = usart_pins(m.mcu_type(), usart->index())) {
            const std::string txd = std::string("P") + pins->tx_port + static_cast<char>('0' + pins->tx_bit);
            const std::string rxd = std::string("P") + pins->rx_port + static_cast<char>('0' + pins->rx_bit);
            timeline_.add_alias(recorder_.trace_pin(m, m.pin(txd)), "serial", s.name + "_txd");
            timeline_.add_alias(recorder_.trace_pin(m, m.pin(rxd)), "serial", s.name + "_rxd");
        }
    }
    for (Mcu* m : board_->mcus()) {
        // Only MCUs on a board's I2C bus: the others have nobody to talk to.
        Twi* twi = m->twi();
        if (twi == nullptr) continue;
        for (const auto& bus : board_->twi_buses()) {
            if (&twi->bus() == bus.get()) recorder_.trace_twi(*m, *twi);
        }
    }
    for (Part* p : board_->parts()) recorder_.trace_part(*p);
}

IdleResult Bench::run_until_idle(double max_seconds, double settle_seconds) {
    return run_until_idle_ps(ps_from_seconds(max_seconds, "run_until_idle"), ps_from_seconds(settle_seconds, "settle time"));
}

bool Bench::still_going(Picoseconds settle_ps, std::vector<std::string>* why) const {
    bool going = false;
    const auto say = [&](std::string text) {
        going = true;
        if (why != nullptr) why->push_back(std::move(text));
        return why == nullptr;  // true: stop looking, the answer is known
    };
    for (const auto& [name, host] : hosts_) {
        // A firmware that says it is busy (a keep-alive while it waits for
        // its heater, or moves) is not done, whatever its answers say.
        if (!host->failed() && host->last_busy_cycle()) {
            const Mcu& m = *port_of(name).mcu;
            const double ago_s = static_cast<double>(m.cycle() - *host->last_busy_cycle()) / m.frequency_hz();
            if (ago_s <= host->line_timeout_s()) {
                char line[96];
                std::snprintf(line, sizeof line, ", %.3f s ago)", ago_s);
                if (say("host " + name + ": the firmware says it is busy (" + quoted_line(host->last_busy_text()) + line)) {
                    return true;
                }
            }
        }
        if (host->finished()) continue;
        std::string text = "host " + name + ": ";
        if (!host->ready()) {
            text += "waiting for the firmware's welcome";
        } else if (host->outstanding_lines() > 0) {
            const GcodeLine& line = host->lines()[host->lines_acknowledged()];
            text += "line " + std::to_string(line.number) + " " + quoted_line(line.text) + " not answered";
        } else if (host->lines_sent() < host->lines().size()) {
            text += std::to_string(host->lines().size() - host->lines_sent()) + " lines still to send";
        } else {
            text += "bytes still to send at their times";
        }
        if (say(text + " (" + std::to_string(host->lines_acknowledged()) + " of " + std::to_string(host->lines().size()) +
                " lines answered)")) {
            return true;
        }
    }
    for (const auto& [name, hand] : hand_) {
        if (!hand.untaken.empty()) {
            if (say("port " + name + ": " + std::to_string(hand.untaken.size()) + " line(s) written by hand not yet taken by the firmware (" +
                    quoted_line(hand.untaken.front().second) + ")")) {
                return true;
            }
        } else if (hand.delivered < hand.written_end) {
            if (say("port " + name + ": bytes written by hand not yet taken by the firmware")) return true;
        }
        if (!hand.unanswered.empty() &&
            say("port " + name + ": " + quoted_line(hand.unanswered.front().second) + ", written by hand, not answered")) {
            return true;
        }
    }
    std::string text;
    for (Part* part : board_->parts()) {
        if (part->still_going(why != nullptr ? &text : nullptr) && say(part->name() + ": " + text)) return true;
    }
    const Picoseconds now = now_ps();
    if (heat_->unsettled(now, why)) {
        going = true;
        if (why == nullptr) return true;
    }
    // Quiet since the later of the last STEP edge and the last line either
    // way on any port: a firmware that answers "ok" at once and starts
    // moving a little later (grbl's planner) is not done yet. 2.5 times the
    // longest step interval: AVR446's first (and last) step interval is
    // 1 / 0.4056 = 2.47 times the next one's (application note AVR446, eq. 15).
    Picoseconds last_activity = last_step_ps_.value_or(0);
    for (const auto& [name, host] : hosts_) {
        if (host->transcript().empty()) continue;
        const Mcu& m = *port_of(name).mcu;
        last_activity = std::max(last_activity, ps_at_cycle(m, host->transcript().back().cycle));
    }
    const Picoseconds quiet_needed = std::max(settle_ps, longest_step_interval_ps_ * 5 / 2);
    const Picoseconds quiet = now - std::min(now, last_activity);
    if (quiet < quiet_needed) {
        char line[160];
        std::snprintf(line, sizeof line, "motion: the last step or line %.3f s ago, done after %.3f s without one",
                      seconds_from_ps(quiet), seconds_from_ps(quiet_needed));
        say(line);
    }
    return going;
}

IdleResult Bench::run_until_idle_ps(Picoseconds max_ps, Picoseconds settle_ps) {
    return noting_what_is_going(run_until_done(max_ps, settle_ps), settle_ps);
}

void Bench::sample_heaters() { heat_->sample(now_ps()); }

IdleResult Bench::noting_what_is_going(IdleResult r, Picoseconds settle_ps) {
    left_going_.clear();
    if (r != IdleResult::Idle) still_going(settle_ps, &left_going_);
    return r;
}

IdleResult Bench::run_until_done(Picoseconds max_ps, Picoseconds settle_ps) {
    const Picoseconds end = add_ps(now_ps(), max_ps);
    // Small slices so idleness is noticed promptly; each is one Lockstep run.
    const Picoseconds slice = std::clamp<Picoseconds>(settle_ps / 4, 10'000'000, kPsPerMs);
    for (;;) {
        for (auto& [name, host] : hosts_) {
            if (host->failed()) return IdleResult::HostFailed;
        }
        const Picoseconds now = now_ps();
        sample_heaters();
        if (!still_going(settle_ps)) return IdleResult::Idle;
        if (now >= end) return IdleResult::TimeLimit;
        if (user_stop_requested()) return IdleResult::Interrupted;
        if (timeline_.overflowed()) return IdleResult::RecorderFull;
        // now < target, and afterwards now_ps() >= target (core/Time.hpp): progress.
        if (board_->run_until_ps(std::min(end, add_ps(now, slice))) == StopReason::Halted) return IdleResult::Halted;
    }
}

IdleResult Bench::run_to_ps(Picoseconds end_ps, const RunSlices& how) {
    const Picoseconds slice_ps =
        how.slice_ps != 0 ? how.slice_ps : std::clamp<Picoseconds>(end_ps / 100, 1'000'000, 10 * kPsPerMs);
    const auto ended = [this, &how](IdleResult r) { return how.until_idle ? noting_what_is_going(r, how.settle_ps) : r; };
    // Each pass ends with now_ps() >= its target > the previous now_ps() (core/Time.hpp).
    while (now_ps() < end_ps) {
        if (user_stop_requested()) return ended(IdleResult::Interrupted);
        if (timeline_.overflowed()) return ended(IdleResult::RecorderFull);
        const Picoseconds target = std::min(end_ps, add_ps(now_ps(), slice_ps));
        if (how.until_idle) {
            const IdleResult r = run_until_done(target - now_ps(), how.settle_ps);
            if (r != IdleResult::TimeLimit) return ended(r);
        } else if (board_->run_until_ps(target) == StopReason::Halted) {
            return IdleResult::Halted;
        }
        if (how.after_slice) how.after_slice();
        if (how.stop_when && how.stop_when()) return IdleResult::Idle;
    }
    return ended(IdleResult::TimeLimit);
}

std::vector<Finding> Bench::findings() const {
    std::vector<Finding> out = board_->findings();
    for (const auto& [name, host] : hosts_) {
        for (const auto& e : host->events()) {
            if (e.kind == HostEventKind::Error && e.line && right_refusals_.count({host.get(), e.line->number}) != 0) continue;
            Finding f;
            f.kind = UartHost::kHostProtocol;
            f.source = name;
            f.cycle = e.cycle;
            f.clock_hz = port_of(name).mcu->frequency_hz();
            f.has_pc = false;
            f.detail = e.message;
            out.push_back(f);
        }
    }
    return out;
}

RunReport Bench::make_report(const std::string& title) const { return make_run_report(*this, title); }

std::vector<bool> Bench::report_signal_mask() const { return avrbench::report_signal_mask(*this); }

std::vector<Mcu*> Bench::mcus() const { return board_->mcus(); }
std::vector<Part*> Bench::parts() const { return board_->parts(); }
std::string Bench::board_path() const { return board_->spec().path; }

std::map<const Part*, std::vector<std::pair<double, double>>> Bench::temperature_targets(const std::vector<Part*>& plants) const {
    // From the G-code the hosts sent (run/HeatTargets.hpp).
    std::map<const Part*, std::vector<std::pair<double, double>>> targets;
    for (const auto& [name, host] : hosts_) {
        const std::uint32_t hz = port_of(name).mcu->frequency_hz();
        for (const auto& e : host->transcript()) {
            if (e.direction != Direction::Sent) continue;
            double degC = 0;
            if (const Part* plant = heated_part_for(plants, e.text, &degC)) {
                targets[plant].emplace_back(static_cast<double>(e.cycle) / hz, degC);
            }
        }
    }
    return targets;
}

// Each serial port's lines: the host's transcript, or the firmware's output.
std::vector<TranscriptLine> Bench::transcript() const {
    std::vector<TranscriptLine> lines;
    for (const auto& port : serial_ports_) {
        const std::uint32_t hz = port.mcu->frequency_hz();
        auto host = hosts_.find(port.name);
        if (host != hosts_.end()) {
            for (const auto& e : host->second->transcript()) {
                lines.push_back({e.cycle, hz, e.direction == Direction::Sent, e.text});
            }
            continue;
        }
        // No host on this port: the firmware's output, one entry per line,
        // stamped with the cycle of the line's first byte.
        std::string line;
        Cycle line_start = 0;
        for (const auto& b : port.link().transmitted()) {
            if (line.empty()) line_start = b.cycle;
            if (b.value == '\n') {
                lines.push_back({line_start, hz, false, line});
                line.clear();
            } else if (b.value != '\r') {
                line.push_back(static_cast<char>(b.value));
            }
        }
        if (!line.empty()) lines.push_back({line_start, hz, false, line});
    }
    return lines;
}

}  // namespace avrbench
