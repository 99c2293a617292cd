#include "debug/RunViews.hpp"

#include <cctype>
#include <cstdio>
#include <optional>

#include "boards/Board.hpp"
#include "core/Errors.hpp"
#include "core/Units.hpp"
#include "periph/ports/McuPins.hpp"
#include "mcu/Mcu.hpp"
#include "parts/Part.hpp"
#include "stimulus/UartHost.hpp"
#include "trace/Timeline.hpp"
#include "run/Bench.hpp"
#include "run/McuRun.hpp"
#include "wiring/Net.hpp"

namespace avrbench {

namespace {

constexpr std::size_t kTimelineEventsShown = 20;
constexpr std::size_t kHostLinesShown = 10;

// Every pin of the MCU's ports as "PB5=1 (out)".
std::string pins_text(Mcu& mcu) {
    std::string out;
    for (char port = 'A'; port <= 'L'; ++port) {
        std::string line;
        for (int bit = 0; bit < 8; ++bit) {
            if (!mcu_has_pin(mcu.mcu_type(), port, bit)) continue;
            Pin& p = mcu.pin(std::string("P") + port + std::to_string(bit));
            line += std::string(line.empty() ? "" : " ") + p.name() + "=" + (p.level() ? "1" : "0") +
                    (p.is_output() ? "(out)" : "");
        }
        if (!line.empty()) out += line + "\n";
    }
    return out.empty() ? "this MCU type's pinout is not known to the bench\n" : out;
}

// The last events still in memory (a streamed VCD has written the older ones).
std::string timeline_text(const Timeline& timeline) {
    const auto& events = timeline.events();
    if (events.empty()) return "no events in memory (older ones are in the VCD)\n";
    std::string out;
    const std::size_t first = events.size() > kTimelineEventsShown ? events.size() - kTimelineEventsShown : 0;
    for (std::size_t i = first; i < events.size(); ++i) {
        const TimelineEvent& e = events[i];
        const SignalInfo& s = timeline.signals()[e.signal];
        char buf[200];
        if (s.kind == SignalKind::Real) {
            std::snprintf(buf, sizeof buf, "cycle %llu  %s.%s = %g\n", static_cast<unsigned long long>(e.cycle),
                          s.scope.c_str(), s.name.c_str(), e.value.real);
        } else {
            std::snprintf(buf, sizeof buf, "cycle %llu  %s.%s = %llu\n", static_cast<unsigned long long>(e.cycle),
                          s.scope.c_str(), s.name.c_str(), static_cast<unsigned long long>(e.value.bits));
        }
        out += buf;
    }
    return out;
}

}  // namespace

DebugRunView board_debug_view(Bench& bench, const UartHost* host, bool replayable) {
    DebugRunView v;
    v.replayable = replayable;
    v.findings = [&bench] { return bench.findings(); };
    v.monitor_help = {"pins                 this MCU's pins (level, output or not)",
                      "nets                 every net of the board and its level",
                      "parts                every part's signals (positions, temperatures, ...)",
                      "uart                 the job's last lines either way",
                      "timeline             the last events recorded"};
    v.monitor = [&bench, host](const std::string& command, Mcu& mcu) -> std::optional<std::string> {
        if (command == "pins") return pins_text(mcu);
        if (command == "nets") {
            std::string out;
            for (const auto& net : bench.board().nets()) out += net->name() + "=" + (net->level() ? "1" : "0") + "\n";
            return out;
        }
        if (command == "parts") {
            std::string out;
            for (Part* p : bench.board().parts()) {
                out += p->name() + ":";
                for (std::size_t i = 0; i < p->signals().size(); ++i) {
                    char buf[96];
                    std::snprintf(buf, sizeof buf, " %s=%g%s", p->signals()[i].name.c_str(), p->signal_value(i),
                                  p->signals()[i].unit.c_str());
                    out += buf;
                }
                out += "\n";
            }
            return out;
        }
        if (command == "uart") {
            if (host == nullptr) return std::string("no job on a serial port\n");
            const auto& lines = host->transcript();
            std::string out;
            const std::size_t first = lines.size() > kHostLinesShown ? lines.size() - kHostLinesShown : 0;
            for (std::size_t i = first; i < lines.size(); ++i) {
                out += std::string(lines[i].direction == Direction::Sent ? "> " : "< ") + lines[i].text + "\n";
            }
            return out.empty() ? "no lines yet\n" : out;
        }
        if (command == "timeline") return timeline_text(bench.timeline());
        return std::nullopt;
    };
    return v;
}

DebugRunView mcu_debug_view(McuRun& run) {
    DebugRunView v;
    v.findings = [&run] { return run.mcu().findings(); };
    v.monitor_help = {"pins                 this MCU's pins (level, output or not)",
                      "timeline             the last events recorded"};
    v.monitor = [&run](const std::string& command, Mcu& mcu) -> std::optional<std::string> {
        if (command == "pins") return pins_text(mcu);
        if (command == "timeline") return timeline_text(run.timeline());
        return std::nullopt;
    };
    return v;
}

namespace {

// "--gdb [MCU=]PORT" items as ports (BadInput naming the item).
std::vector<DebugOptions::Port> parse_gdb_ports(const std::vector<std::string>& items) {
    std::vector<DebugOptions::Port> out;
    for (const auto& item : items) {
        const auto eq = item.find('=');
        DebugOptions::Port p;
        const std::string number = eq == std::string::npos ? item : item.substr(eq + 1);
        if (eq != std::string::npos) p.mcu = item.substr(0, eq);
        std::size_t used = 0;
        int port = -1;
        try {
            port = std::stoi(number, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != number.size() || number.empty() || port < 0 || port > 65535) {
            throw BadInput("--gdb '" + item + "': not [MCU=]PORT with a TCP port 0..65535 (0: any free port)");
        }
        p.port = port;
        for (const auto& other : out) {
            if (other.mcu == p.mcu) throw BadInput("--gdb: MCU " + (p.mcu.empty() ? "(first)" : p.mcu) + " given twice");
        }
        out.push_back(p);
    }
    return out;
}

}  // namespace

std::optional<DebugOptions> debug_options(const DebugArgs& args) {
    if (args.gdb.empty()) {
        if (args.break_at_finding || !args.break_at.empty() || !args.break_at_cycle.empty()) {
            throw BadInput("--break-at-finding, --break-at and --break-at-cycle need --gdb [MCU=]PORT");
        }
        return std::nullopt;
    }
    DebugOptions o;
    o.ports = parse_gdb_ports(args.gdb);
    o.break_at_finding = args.break_at_finding;
    if (!args.break_at.empty()) o.break_at_ps = parse_duration_ps(args.break_at, "--break-at");
    if (!args.break_at_cycle.empty()) {
        std::size_t used = 0;
        unsigned long long cycle = 0;
        try {
            cycle = std::stoull(args.break_at_cycle, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != args.break_at_cycle.size() || !std::isdigit(static_cast<unsigned char>(args.break_at_cycle[0]))) {
            throw BadInput("--break-at-cycle '" + args.break_at_cycle + "': not a cycle number");
        }
        o.break_at_cycle = cycle;
    }
    o.announce = [](const std::string& line) {
        std::fprintf(stderr, "%s\n", line.c_str());
        std::fflush(stderr);
    };
    return o;
}

}  // namespace avrbench
