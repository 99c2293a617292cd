#include "debug/Debugger.hpp"

#include <simavr/avr_eeprom.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_core.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>

#include "core/Errors.hpp"
#include "mcu/Lockstep.hpp"
#include "mcu/Mcu.hpp"
#include "core/Scheduler.hpp"
#include "core/UserStop.hpp"
#include "debug/DataAccess.hpp"
#include "debug/GdbConnection.hpp"

namespace avrbench {

namespace {

// avr-gdb's address spaces in one 32-bit space (gdb/avr-tdep.c's layout,
// also simavr's and every AVR stub's): flash from 0, data from 0x800000,
// EEPROM from 0x810000.
constexpr std::uint32_t kDataBase = 0x800000;
constexpr std::uint32_t kEepromBase = 0x810000;
constexpr std::uint32_t kSpaceSize = 0x10000;
// avr-gdb's registers: r0..r31, SREG, SP (2 bytes), PC (4 bytes, a byte address).
constexpr unsigned kSregNumber = 32, kSpNumber = 33, kPcNumber = 34;
constexpr std::size_t kRegisterBytes = 32 + 1 + 2 + 4;
constexpr std::uint64_t kNever = ~std::uint64_t{0};
constexpr std::uint32_t kInterruptPollSteps = 4096;
// Instructions between replay checkpoints (a cycle number each).
constexpr std::uint64_t kCheckpointInstructions = 4096;
// A replay's hook comes back this many cycles before its checkpoint: more
// than an instruction plus an interrupt's entry (5 + 5), so the timer that
// brings it fires before the checkpoint's instruction boundary.
constexpr Cycle kCheckpointLeadCycles = 16;

std::uint32_t parse_hex(const std::string& s, std::size_t& at) {
    std::uint32_t v = 0;
    while (at < s.size() && std::isxdigit(static_cast<unsigned char>(s[at])) != 0) {
        const char c = s[at];
        v = v * 16 + static_cast<std::uint32_t>(c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10);
        ++at;
    }
    return v;
}

std::string hex_u32(std::uint32_t v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%x", v);
    return buf;
}

std::uint8_t sreg_of(avr_t* avr) {
    std::uint8_t sreg = 0;
    for (int i = 0; i < 8; ++i) {
        if (avr->sreg[i] != 0) sreg = static_cast<std::uint8_t>(sreg | (1u << i));
    }
    return sreg;
}

void set_sreg(avr_t* avr, std::uint8_t value) {
    for (int i = 0; i < 8; ++i) avr->sreg[i] = static_cast<std::uint8_t>((value >> i) & 1u);
    avr->data[R_SREG] = value;
}

// An EEPROM byte of the MCU, nullptr past its end. Straight from the
// module's array: simavr 1.6's EEPROM ioctls report failure when they
// succeed, and a flash module registered first may swallow them (both fixed
// upstream after 1.6, commit 4fc6932 "flash+eeprom: fix ioctl handling").
std::uint8_t* eeprom_cell(Mcu& mcu, std::uint32_t offset) {
    auto* eeprom = reinterpret_cast<avr_eeprom_t*>(mcu.io_module("eeprom"));
    if (eeprom == nullptr || eeprom->eeprom == nullptr || offset >= eeprom->size) return nullptr;
    return eeprom->eeprom + offset;
}

}  // namespace

struct Debugger::Target {
    std::string mcu_name;
    int requested_port = 0;
    std::unique_ptr<GdbListener> listener;
    std::unique_ptr<GdbConnection> conn;
    Mcu* mcu = nullptr;
    std::uint64_t executed = 0;  // instructions this MCU executed since power-on, in this run
    std::set<std::uint32_t> breakpoints;  // flash byte addresses
    struct Watch {
        std::uint32_t address, length;  // data space
        char type;                      // '2' write, '3' read, '4' access (Z packets)
    };
    std::vector<Watch> watches;
    bool waiting = false;   // avr-gdb waits for a stop reply
    bool detached = false;  // nobody debugs it (any more)
    std::optional<std::uint64_t> stop_at;  // in front of this instruction (a step, power-on)
    std::uint64_t resumed_at = kNever;     // where it went on from: that breakpoint does not stop it again
    std::string pending_reply;             // a stop decided after an instruction (a watchpoint, an interrupt)
    std::string last_reply = "S05";
    std::optional<Finding> finding;  // why it stopped, when a finding was why
    bool halted = false;
    // Every kCheckpointInstructions-th instruction's start cycle (position ->
    // cycle), from the runs so far: a replay runs to the last one before
    // where it goes at full speed, without the hook, and goes on from there.
    std::map<std::uint64_t, Cycle> checkpoints;
    std::optional<std::pair<std::uint64_t, Cycle>> seeking;  // the checkpoint a replay's hook waits for
};

struct Debugger::Edit {
    std::size_t target;
    unsigned run;  // the run it was made in (replays apply it again)
    std::uint64_t position;
    bool is_register;
    std::uint32_t where;  // register number or gdb address
    std::string bytes;
};

Debugger::Debugger(DebugOptions options) : options_(std::move(options)) {
    for (const auto& p : options_.ports) {
        auto t = std::make_unique<Target>();
        t->mcu_name = p.mcu;
        t->requested_port = p.port;
        t->stop_at = 0;  // power-on: avr-gdb finds the MCU stopped in front of its first instruction
        targets_.push_back(std::move(t));
    }
}

Debugger::~Debugger() = default;

void Debugger::listen() {
    for (auto& t : targets_) {
        t->listener = std::make_unique<GdbListener>(t->requested_port);
        if (options_.announce) {
            options_.announce("gdb: MCU " + (t->mcu_name.empty() ? std::string("(first)") : t->mcu_name) +
                              " waits for avr-gdb on 127.0.0.1:" + std::to_string(t->listener->port()) +
                              " (target remote :" + std::to_string(t->listener->port()) + ")");
        }
    }
}

void Debugger::check_targets(const std::vector<Mcu*>& mcus) const {
    for (const auto& t : targets_) {
        if (t->mcu_name.empty()) continue;
        bool found = false;
        for (Mcu* m : mcus) found = found || m->name() == t->mcu_name;
        if (found) continue;
        std::string names;
        for (Mcu* m : mcus) names += (names.empty() ? "" : ", ") + m->name();
        throw BadInput("--gdb: no MCU named '" + t->mcu_name + "' on this board (it has " + names + ")");
    }
}

void Debugger::attach(const std::vector<Mcu*>& mcus, DebugRunView view) {
    mcus_ = mcus;
    view_ = std::move(view);
    ++runs_;
    for (auto& t : targets_) {
        t->mcu = nullptr;
        for (Mcu* m : mcus) {
            if (t->mcu_name.empty() ? m == mcus.front() : m->name() == t->mcu_name) t->mcu = m;
        }
        if (t->mcu == nullptr) {
            std::string names;
            for (Mcu* m : mcus) names += (names.empty() ? "" : ", ") + m->name();
            throw BadInput("--gdb: no MCU named '" + t->mcu_name + "' on this board (it has " + names + ")");
        }
        t->mcu_name = t->mcu->name();
        t->executed = 0;
        t->halted = false;
        t->pending_reply.clear();
        t->seeking.reset();
        if (!resume_from_checkpoint(*t)) t->mcu->set_debug_hook(this);
    }
    findings_seen_ = findings_recorded();
    if (connected_) return;
    for (auto& t : targets_) {
        const int fd = t->listener->accept_one(options_.connect_timeout);
        if (fd < 0) {
            throw BadInput("--gdb: no debugger connected to 127.0.0.1:" + std::to_string(t->listener->port()) +
                           " (MCU " + t->mcu_name + ") within " + std::to_string(options_.connect_timeout.count()) + " s");
        }
        t->conn = std::make_unique<GdbConnection>(fd);
    }
    connected_ = true;
}

void Debugger::detach() {
    // The run's MCUs may be gone already (a scenario's Bench ends inside
    // run_scenario, a replay unwinds through it): only forget them.
    for (auto& t : targets_) t->mcu = nullptr;
    mcus_.clear();
}

void Debugger::run_ended(int exit_code) {
    char exited[8];
    std::snprintf(exited, sizeof exited, "W%02x", static_cast<unsigned>(exit_code) & 0xFF);
    for (auto& t : targets_) {
        if (!t->conn || !t->conn->open()) continue;
        // W: exited with the front end's exit code; X0b: killed by SIGSEGV (it crashed).
        if (t->waiting) t->conn->send_packet(t->halted ? "X0b" : exited);
        t->conn->close();
    }
}

void Debugger::run_replays(const std::function<void()>& make_and_run) {
    for (;;) {
        try {
            make_and_run();
            return;
        } catch (const DebugReplay&) {
            detach();
        }
    }
}

// A reverse step of the only debugged MCU, with no write of the debugger's
// before where it goes: run without the hook (fast path, idle loops skipped:
// exact, the run loop's tests prove it) to just before the last checkpoint
// on the way, then hook in and find the checkpoint's instruction by its cycle.
bool Debugger::resume_from_checkpoint(Target& t) {
    if (!replay_ || replay_->target != &t || targets_.size() != 1) return false;
    replay_->scan_start = 0;
    std::uint64_t limit = replay_->position;
    if (replay_->scan) limit = replay_->position > replay_->window ? replay_->position - replay_->window : 0;
    for (const Edit& e : edits_) limit = std::min(limit, e.position);
    auto it = t.checkpoints.upper_bound(limit);
    if (it == t.checkpoints.begin()) return false;
    --it;
    const auto [position, cycle] = *it;
    if (position == 0 || cycle < kCheckpointLeadCycles) return false;
    t.seeking = std::make_pair(position, cycle);
    replay_->scan_start = position;
    Target* const target = &t;
    t.mcu->scheduler().at(cycle - kCheckpointLeadCycles, [this, target](Cycle) { target->mcu->set_debug_hook(this); });
    return true;
}

Debugger::Target* Debugger::target_of(Mcu& mcu) {
    for (auto& t : targets_) {
        if (t->mcu == &mcu) return t.get();
    }
    return nullptr;
}

void Debugger::poll_interrupts() {
    for (auto& t : targets_) {
        if (t->detached || !t->waiting || !t->conn) continue;
        if (t->conn->poll_interrupt()) t->pending_reply = "S02";  // SIGINT, as a Ctrl-C in avr-gdb
        if (!t->conn->open()) debugger_lost(*t);
    }
}

bool Debugger::stop_condition(Target& t, std::string& reply) {
    if (t.detached) return false;
    if (!t.pending_reply.empty()) {
        reply = std::move(t.pending_reply);
        t.pending_reply.clear();
        return true;
    }
    // Before a step's or breakpoint's stop: a finding made by this
    // instruction is told now, once, not on the next resume (a stepi onto it
    // would leave it for the next continue to stop at again, an instruction later).
    if (findings_recorded() != findings_seen_) {
        findings_seen_ = findings_recorded();
        if (options_.break_at_finding && view_.findings) {
            const auto all = view_.findings();
            if (!all.empty()) {
                t.finding = all.back();
                t.conn->send_packet("O" + to_hex("avrbench: stopped at a finding: " + all.back().describe() + "\n"));
                t.stop_at.reset();
                reply = "S05";
                return true;
            }
        }
    }
    if (t.stop_at && t.executed >= *t.stop_at) {
        t.stop_at.reset();
        reply = "S05";
        return true;
    }
    avr_t* avr = t.mcu->avr();
    if (t.executed != t.resumed_at && t.breakpoints.count(avr->pc) != 0) {
        reply = "S05";
        return true;
    }
    if (!break_at_done_ && (options_.break_at_cycle || options_.break_at_ps) && &t == targets_.front().get()) {
        const Cycle at = options_.break_at_cycle ? *options_.break_at_cycle : cycle_at_ps(*t.mcu, *options_.break_at_ps);
        if (t.mcu->cycle() >= at) {
            break_at_done_ = true;
            reply = "S05";
            return true;
        }
    }
    return false;
}

void Debugger::before_step(Mcu& mcu) {
    Target* const tp = target_of(mcu);
    if (tp == nullptr) return;
    Target& t = *tp;
    if (--poll_countdown_ == 0) {
        poll_countdown_ = kInterruptPollSteps;
        poll_interrupts();
    }
    avr_t* const avr = mcu.avr();
    if (avr->state != cpu_Running) return;  // asleep: no instruction to stop in front of
    if (t.seeking) {
        // Hooked in again just before a checkpoint: its instruction is the one
        // that starts at its cycle.
        if (avr->cycle < t.seeking->second) return;
        if (avr->cycle != t.seeking->second) {
            throw std::logic_error("debugger replay: no instruction starts at the checkpoint's cycle " +
                                   std::to_string(t.seeking->second));
        }
        t.executed = t.seeking->first;
        t.seeking.reset();
    }
    if (t.executed % kCheckpointInstructions == 0) t.checkpoints.emplace(t.executed, avr->cycle);
    // A replay makes the debugger's own writes again where they were made.
    if (runs_ > 1) {
        for (const Edit& e : edits_) {
            if (e.run == runs_ || targets_[e.target].get() != &t || e.position != t.executed) continue;
            if (e.is_register) {
                write_register(t, e.where, e.bytes, false);
            } else {
                write_memory(t, e.where, e.bytes, false);
            }
        }
    }
    if (replay_) {
        findings_seen_ = findings_recorded();
        if (replay_->target == &t) {
            if (replay_->scan && t.executed < replay_->position && t.breakpoints.count(avr->pc) != 0) {
                replay_->last_hit = t.executed;
                replay_->reply = "S05";
            }
            t.pending_reply.clear();
            if (t.executed == replay_->position) {
                if (replay_->scan && !replay_->last_hit && replay_->scan_start > 0) {
                    // Nothing since the checkpoint the scan began at: look further back.
                    replay_->window *= 4;
                    throw DebugReplay{};
                }
                if (replay_->scan) {
                    // The last hit before where reverse-continue started; none: the beginning.
                    Replay go;
                    go.target = &t;
                    go.position = replay_->last_hit.value_or(0);
                    go.reply = replay_->last_hit ? replay_->reply : "T05replaylog:begin;";
                    replay_ = go;
                    throw DebugReplay{};
                }
                const std::string reply = replay_->reply;
                replay_.reset();
                serve(t, reply);
            }
        }
    } else {
        std::string reply;
        if (stop_condition(t, reply)) serve(t, reply);
    }
    // Watchpoints: the accesses of the instruction about to execute; a hit
    // stops in front of the next one (where the access has happened), or,
    // scanning backwards, in front of this one.
    if (!t.watches.empty() && !t.detached && (!replay_ || replay_->target == &t)) {
        const std::uint32_t pc = avr->pc;
        const auto word = [avr](std::uint32_t at) {
            return at + 1 <= avr->flashend ? static_cast<std::uint16_t>(avr->flash[at] | (avr->flash[at + 1] << 8)) : std::uint16_t{0};
        };
        for (const DataAccess& a : data_accesses(word(pc), word(pc + 2), avr->data)) {
            for (const auto& w : t.watches) {
                if (a.address < w.address || a.address >= w.address + w.length) continue;
                if (w.type == '2' && !a.write) continue;
                if (w.type == '3' && a.write) continue;
                const char* kind = w.type == '2' ? "watch" : w.type == '3' ? "rwatch" : "awatch";
                const std::string reply = std::string("T05") + kind + ":" + hex_u32(kDataBase + w.address) + ";";
                if (replay_ && replay_->scan) {
                    // Going backwards a watchpoint stops in front of the access
                    // (the value as it was before it), as gdb's own record does.
                    if (t.executed < replay_->position) {
                        replay_->last_hit = t.executed;
                        replay_->reply = reply;
                    }
                } else {
                    t.pending_reply = reply;
                }
            }
        }
    }
    ++t.executed;
}

void Debugger::halted(Mcu& mcu) {
    Target* const t = target_of(mcu);
    if (t == nullptr || t->detached || replay_) return;
    t->halted = true;
    if (!mcu.findings().empty()) {
        t->finding = mcu.findings().back();
        if (t->conn) t->conn->send_packet("O" + to_hex("avrbench: the MCU halted: " + t->finding->describe() + "\n"));
    }
    serve(*t, "T0b");  // SIGSEGV: a crash
}

void Debugger::serve(Target& t, const std::string& stop_reply) {
    t.last_reply = stop_reply;
    if (t.waiting) t.conn->send_packet(stop_reply);
    t.waiting = false;
    for (;;) {
        const auto packet = t.conn->read_packet();
        if (!packet) {
            debugger_lost(t);
            return;
        }
        if (!handle(t, *packet)) return;
    }
}

std::string Debugger::read_registers(Target& t) const {
    avr_t* avr = t.mcu->avr();
    std::string r(kRegisterBytes, '\0');
    for (unsigned i = 0; i < 32; ++i) r[i] = static_cast<char>(avr->data[i]);
    r[32] = static_cast<char>(sreg_of(avr));
    r[33] = static_cast<char>(avr->data[R_SPL]);
    r[34] = static_cast<char>(avr->data[R_SPH]);
    // A crash shows at the instruction that crashed, as a hardware debugger's trap would.
    const std::uint32_t pc = t.halted && t.finding && t.finding->has_pc ? t.finding->pc_bytes : avr->pc;
    for (unsigned i = 0; i < 4; ++i) r[35 + i] = static_cast<char>((pc >> (8 * i)) & 0xFF);
    return r;
}

void Debugger::write_register(Target& t, unsigned number, const std::string& bytes, bool record) {
    avr_t* avr = t.mcu->avr();
    const auto byte = [&bytes](std::size_t i) { return i < bytes.size() ? static_cast<std::uint8_t>(bytes[i]) : std::uint8_t{0}; };
    if (number < 32) {
        avr->data[number] = byte(0);
    } else if (number == kSregNumber) {
        set_sreg(avr, byte(0));
    } else if (number == kSpNumber) {
        avr->data[R_SPL] = byte(0);
        avr->data[R_SPH] = byte(1);
    } else if (number == kPcNumber) {
        avr->pc = static_cast<std::uint32_t>(byte(0) | (byte(1) << 8) | (byte(2) << 16)) & ~1u;
    } else {
        return;
    }
    if (record) {
        edits_.push_back({static_cast<std::size_t>(std::find_if(targets_.begin(), targets_.end(),
                                                                [&t](const auto& p) { return p.get() == &t; }) -
                                                   targets_.begin()),
                          runs_, t.executed, true, number, bytes});
    }
}

std::string Debugger::read_memory(Target& t, std::uint32_t address, std::uint32_t length) const {
    avr_t* avr = t.mcu->avr();
    std::string out;
    for (std::uint32_t i = 0; i < length; ++i) {
        const std::uint32_t a = address + i;
        if (a < kDataBase) {
            if (a > avr->flashend) break;
            out += static_cast<char>(avr->flash[a]);
        } else if (a < kDataBase + kSpaceSize) {
            const std::uint32_t d = a - kDataBase;
            if (d > avr->ramend) break;
            out += static_cast<char>(d == R_SREG ? sreg_of(avr) : avr->data[d]);
        } else if (a >= kEepromBase && a < kEepromBase + kSpaceSize) {
            std::uint8_t* const cell = eeprom_cell(*t.mcu, a - kEepromBase);
            if (cell == nullptr) break;
            out += static_cast<char>(*cell);
        } else {
            break;
        }
    }
    return out;
}

bool Debugger::write_memory(Target& t, std::uint32_t address, const std::string& bytes, bool record) {
    avr_t* avr = t.mcu->avr();
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        const std::uint32_t a = address + static_cast<std::uint32_t>(i);
        const auto b = static_cast<std::uint8_t>(bytes[i]);
        if (a < kDataBase) {
            if (a > avr->flashend) return false;
            avr->flash[a] = b;
            t.mcu->flash_written(a, a + 1);
        } else if (a < kDataBase + kSpaceSize) {
            const std::uint32_t d = a - kDataBase;
            if (d > avr->ramend) return false;
            if (d == R_SREG) {
                set_sreg(avr, b);
            } else {
                avr->data[d] = b;
            }
        } else if (a >= kEepromBase && a < kEepromBase + kSpaceSize) {
            std::uint8_t* const cell = eeprom_cell(*t.mcu, a - kEepromBase);
            if (cell == nullptr) return false;
            *cell = b;
        } else {
            return false;
        }
    }
    if (record) {
        const auto index = static_cast<std::size_t>(
            std::find_if(targets_.begin(), targets_.end(), [&t](const auto& p) { return p.get() == &t; }) - targets_.begin());
        edits_.push_back({index, runs_, t.executed, false, address, bytes});
    }
    return true;
}

void Debugger::replay_to(Target& t, std::uint64_t position, bool scan_for_hits) {
    if (!view_.replayable) {
        t.conn->send_packet("O" + to_hex("avrbench: this run cannot go backwards: its inputs (a pty) do not come again\n"));
        t.conn->send_packet("E01");
        return;
    }
    Replay r;
    r.target = &t;
    r.position = position;
    r.scan = scan_for_hits;
    r.window = 4 * kCheckpointInstructions;
    r.reply = "S05";
    replay_ = r;
    t.waiting = true;
    throw DebugReplay{};
}

std::string Debugger::monitor(Target& t, const std::string& command) {
    Mcu& m = *t.mcu;
    if (command == "help" || command.empty()) {
        std::string out =
            "avrbench monitor commands:\n"
            "  time                 the cycle, simulated time and instructions of this MCU; replays so far\n"
            "  findings             every finding of the run so far (why --break-at-finding stopped)\n"
            "  break-at-finding on|off\n";
        for (const auto& line : view_.monitor_help) out += "  " + line + "\n";
        return out;
    }
    if (command == "time" || command == "cycle") {
        char buf[200];
        std::snprintf(buf, sizeof buf, "MCU %s: cycle %llu, %.9f s, %llu instructions since power-on (replays: %u)\n",
                      m.name().c_str(), static_cast<unsigned long long>(m.cycle()), m.seconds(),
                      static_cast<unsigned long long>(t.executed), runs_ - 1);
        return buf;
    }
    if (command == "findings" || command == "finding") {
        std::string out;
        const auto all = view_.findings ? view_.findings() : m.findings();
        for (const auto& f : all) out += f.describe() + "\n";
        if (t.finding) out += "stopped for: " + t.finding->describe() + "\n";
        return out.empty() ? "no findings so far\n" : out;
    }
    if (command == "break-at-finding on" || command == "break-at-finding off") {
        options_.break_at_finding = command.back() == 'n';
        return std::string("break-at-finding ") + (options_.break_at_finding ? "on" : "off") + "\n";
    }
    if (view_.monitor) {
        if (auto out = view_.monitor(command, m)) return *out;
    }
    return "unknown monitor command '" + command + "' (monitor help lists them)\n";
}

// Registers: g, G, p, P. Returns the reply.
std::string Debugger::handle_registers(Target& t, const std::string& p) {
    if (p[0] == 'g') return to_hex(read_registers(t));
    if (p[0] == 'G') {
        const std::string bytes = from_hex(p.substr(1));
        if (bytes.size() < 35) return "E01";
        for (unsigned n = 0; n < 32; ++n) write_register(t, n, bytes.substr(n, 1), true);
        write_register(t, kSregNumber, bytes.substr(32, 1), true);
        write_register(t, kSpNumber, bytes.substr(33, 2), true);
        if (bytes.size() >= 39) write_register(t, kPcNumber, bytes.substr(35, 4), true);
        return "OK";
    }
    std::size_t at = 1;
    const unsigned n = parse_hex(p, at);
    if (n > kPcNumber) return "E01";
    if (p[0] == 'p') {
        const std::string regs = read_registers(t);
        const std::size_t offset = n < 33 ? n : n == kSpNumber ? 33 : 35;
        const std::size_t size = n < 33 ? 1 : n == kSpNumber ? 2 : 4;
        return to_hex(regs.substr(offset, size));
    }
    write_register(t, n, from_hex(p.substr(std::min(p.size(), at + 1))), true);
    return "OK";
}

// Memory: m, M, X. Returns the reply.
std::string Debugger::handle_memory(Target& t, const std::string& p) {
    std::size_t at = 1;
    const std::uint32_t address = parse_hex(p, at);
    ++at;
    if (p[0] == 'm') {
        const std::uint32_t length = std::min<std::uint32_t>(parse_hex(p, at), 2048);
        const std::string bytes = read_memory(t, address, length);
        return bytes.empty() && length > 0 ? "E01" : to_hex(bytes);
    }
    const std::uint32_t length = parse_hex(p, at);
    const std::string data = p.substr(std::min(p.size(), at + 1));
    const std::string bytes = p[0] == 'M' ? from_hex(data) : data;
    return bytes.size() == length && write_memory(t, address, bytes, true) ? "OK" : "E01";
}

// Breakpoints and watchpoints: Z and z. Returns the reply ("" unsupported).
std::string Debugger::handle_breakpoints(Target& t, const std::string& p) {
    std::size_t at = 3;
    const char type = p.size() > 1 ? p[1] : '?';
    const std::uint32_t address = parse_hex(p, at);
    ++at;
    const std::uint32_t length = parse_hex(p, at);
    const bool insert = p[0] == 'Z';
    if (type == '0' || type == '1') {
        if (insert) {
            t.breakpoints.insert(address);
        } else {
            t.breakpoints.erase(address);
        }
        return "OK";
    }
    if (type < '2' || type > '4' || address < kDataBase || address >= kDataBase + kSpaceSize) return "";
    const Target::Watch w{address - kDataBase, std::max<std::uint32_t>(length, 1), type};
    if (insert) {
        t.watches.push_back(w);
    } else {
        std::erase_if(t.watches, [&w](const Target::Watch& x) {
            return x.address == w.address && x.length == w.length && x.type == w.type;
        });
    }
    return "OK";
}

// Queries and settings (q..., Q..., v...): the reply ("" unsupported).
std::string Debugger::handle_query(Target& t, const std::string& p) {
    GdbConnection& c = *t.conn;
    if (p.rfind("qSupported", 0) == 0) return "PacketSize=1000;QStartNoAckMode+;ReverseStep+;ReverseContinue+";
    if (p == "QStartNoAckMode") {
        c.send_packet("OK");
        c.set_no_ack();
        return {};  // answered before the mode changed
    }
    if (p == "qAttached") return "1";
    if (p == "qC") return "QC1";
    if (p == "qfThreadInfo") return "m1";
    if (p == "qsThreadInfo") return "l";
    if (p.rfind("qSymbol", 0) == 0) return "OK";
    if (p.rfind("qRcmd,", 0) == 0) {
        c.send_packet("O" + to_hex(monitor(t, from_hex(p.substr(6)))));
        return "OK";
    }
    return "";
}

// Run control: c, s, bs, bc, D, k, vKill. False: the target runs again.
bool Debugger::handle_run_control(Target& t, const std::string& p) {
    GdbConnection& c = *t.conn;
    const auto resume = [&t] {
        t.waiting = true;
        t.finding.reset();
        t.resumed_at = t.executed;
    };
    if (p[0] == 'c') {
        if (p.size() > 1) {  // continue at an address: a write of PC, made again by replays
            std::size_t at = 1;
            const std::uint32_t pc = parse_hex(p, at);
            write_register(t, kPcNumber, std::string{static_cast<char>(pc & 0xFF), static_cast<char>((pc >> 8) & 0xFF),
                                                     static_cast<char>((pc >> 16) & 0xFF)},
                           true);
        }
        resume();
        return false;
    }
    if (p[0] == 's') {
        resume();
        t.stop_at = t.executed + 1;
        return false;
    }
    if (p == "bs" || p == "bc") {
        if (t.executed == 0) {
            c.send_packet("T05replaylog:begin;");
            return true;
        }
        replay_to(t, p == "bs" ? t.executed - 1 : t.executed, p == "bc");
        return true;  // not replayable: it said so and stays stopped
    }
    if (p[0] == 'D') {
        c.send_packet("OK");
        t.detached = true;
        t.breakpoints.clear();
        t.watches.clear();
        c.close();
        return false;
    }
    // k, vKill: the program ends (the run stops as at a Ctrl-C).
    if (p[0] == 'v') c.send_packet("OK");
    killed_ = true;
    for (auto& other : targets_) other->detached = true;
    request_user_stop();
    t.mcu->request_stop();
    c.close();
    return false;
}

// avr-gdb went away without detaching (it was killed, its terminal closed):
// nobody will look at the run any more, so it stops as at a kill, its
// outputs written, rather than running on to its time limit unwatched.
void Debugger::debugger_lost(Target& t) {
    killed_ = true;
    for (auto& other : targets_) {
        other->detached = true;
        other->breakpoints.clear();
        other->watches.clear();
    }
    request_user_stop();
    if (t.mcu != nullptr) t.mcu->request_stop();
}

bool Debugger::handle(Target& t, const std::string& p) {
    GdbConnection& c = *t.conn;
    if (p == "\x03") return true;  // already stopped
    switch (p[0]) {
        case '?': c.send_packet(t.last_reply); return true;
        case 'g': case 'G': case 'p': case 'P': c.send_packet(handle_registers(t, p)); return true;
        case 'm': case 'M': case 'X': c.send_packet(handle_memory(t, p)); return true;
        case 'Z': case 'z': c.send_packet(handle_breakpoints(t, p)); return true;
        case 'c': case 's': case 'D': case 'k': return handle_run_control(t, p);
        case 'b':
            if (p == "bs" || p == "bc") return handle_run_control(t, p);
            break;
        case 'H': case 'T': c.send_packet("OK"); return true;
        default: break;
    }
    if (p.rfind("vKill", 0) == 0) return handle_run_control(t, p);
    const std::string reply = handle_query(t, p);
    if (p != "QStartNoAckMode") c.send_packet(reply);
    return true;
}

}  // namespace avrbench
