// A GDB remote server on the MCUs of a run: avr-gdb (Debian gdb-avr)
// attaches over TCP, one port per MCU, and breaks (software and hardware
// breakpoints on flash addresses), steps, continues, reads and writes
// registers, SRAM, I/O, flash and EEPROM, and stops on RAM watchpoints at
// the instruction that made the access. While one MCU is stopped the whole
// board is: the debugger is served from inside the run loop (core/
// DebugHook.hpp), so simulated time does not move while a person thinks.
//
// Runs are deterministic, so going backwards is going forwards again:
// reverse-stepi and reverse-continue replay the run from power-on (a new run
// of the same inputs, made by the front end) to the instruction wanted, with
// the debugger's own writes to memory and registers applied again where they
// were made. docs/DEBUGGING.md.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "mcu/DebugHook.hpp"
#include "core/Finding.hpp"
#include "core/Time.hpp"

namespace avrbench {

class GdbConnection;
class GdbListener;
class Mcu;

struct DebugOptions {
    struct Port {
        std::string mcu;  // "" = the board's first MCU
        int port = 0;     // 0 = a free port, announced
    };
    std::vector<Port> ports;
    bool break_at_finding = false;            // stop at the first finding of the run
    std::optional<Picoseconds> break_at_ps;   // stop at the first instruction at or after this time
    std::optional<Cycle> break_at_cycle;      // ... or this cycle (of the first debugged MCU)
    std::chrono::seconds connect_timeout{300};
    // "gdb: MCU x listening on 127.0.0.1:PORT" lines, before the run waits for avr-gdb.
    std::function<void(const std::string&)> announce;
};

// What the debugger may tell about the run besides the MCU (monitor commands).
struct DebugRunView {
    std::function<std::vector<Finding>()> findings;
    // Board-level monitor commands ("pins", "board", "uart", "timeline"):
    // their output, or nullopt for a command it does not know.
    std::function<std::optional<std::string>(const std::string& command, Mcu& mcu)> monitor;
    std::vector<std::string> monitor_help;  // one line per command it knows
    bool replayable = true;                 // false: inputs that do not come again (a pty)
};

// Thrown out of the run loop when the debugger needs the run replayed from
// power-on; the front end makes a new run of the same inputs, attaches it
// and runs it (Debugger::run_replays does exactly that).
struct DebugReplay {};

class Debugger final : public DebugHook {
public:
    explicit Debugger(DebugOptions options);
    ~Debugger() override;
    Debugger(const Debugger&) = delete;
    Debugger& operator=(const Debugger&) = delete;

    // Opens every port and announces it (BadInput when one cannot be had).
    void listen();
    // BadInput for a port's MCU the board does not have (before listen()).
    void check_targets(const std::vector<Mcu*>& mcus) const;
    // Each run (the first and every replay): its MCUs in board order. The
    // first waits for avr-gdb on every port (BadInput after the timeout).
    void attach(const std::vector<Mcu*>& mcus, DebugRunView view);
    // The run's objects are gone or about to go (its MCUs are not touched).
    void detach();
    // The run ended (its time was up, the MCU halted or the user stopped it):
    // every debugger waiting for a stop hears that the program exited, with
    // the exit code the front end returns (RSP 'W', so gdb prints
    // "exited with code 03"), or was killed by SIGSEGV if its MCU crashed.
    void run_ended(int exit_code);
    // True once a debugger killed the program ('k'): the front end reports an interrupted run.
    bool killed() const { return killed_; }

    // Makes runs with `make_and_run` (which builds a run, attaches it, runs
    // it and detaches it) until one ends without a replay request.
    void run_replays(const std::function<void()>& make_and_run);

    void before_step(Mcu& mcu) override;
    void halted(Mcu& mcu) override;

private:
    struct Target;
    struct Edit;
    Target* target_of(Mcu& mcu);
    bool resume_from_checkpoint(Target& t);
    void serve(Target& t, const std::string& stop_reply);
    void debugger_lost(Target& t);
    bool handle(Target& t, const std::string& packet);  // false: the target runs again
    std::string handle_registers(Target& t, const std::string& packet);
    std::string handle_memory(Target& t, const std::string& packet);
    std::string handle_breakpoints(Target& t, const std::string& packet);
    std::string handle_query(Target& t, const std::string& packet);
    bool handle_run_control(Target& t, const std::string& packet);
    std::string read_registers(Target& t) const;
    void write_register(Target& t, unsigned number, const std::string& bytes, bool record);
    std::string read_memory(Target& t, std::uint32_t address, std::uint32_t length) const;
    bool write_memory(Target& t, std::uint32_t address, const std::string& bytes, bool record);
    std::string monitor(Target& t, const std::string& command);
    void replay_to(Target& t, std::uint64_t position, bool scan_for_hits);
    bool stop_condition(Target& t, std::string& reply);
    void poll_interrupts();

    DebugOptions options_;
    std::vector<std::unique_ptr<Target>> targets_;
    std::vector<Edit> edits_;
    DebugRunView view_;
    std::vector<Mcu*> mcus_;
    bool connected_ = false;
    bool killed_ = false;
    bool break_at_done_ = false;
    std::uint64_t findings_seen_ = 0;
    std::uint32_t poll_countdown_ = 4096;
    // A replay in progress: which target, to which position, and whether it
    // looks for the last breakpoint or watchpoint hit before it (reverse-continue).
    struct Replay {
        Target* target = nullptr;
        std::uint64_t position = 0;
        bool scan = false;
        // A scan looks at the last `window` instructions before `position`
        // (from the checkpoint at or before their start), growing the window
        // while it finds nothing; scan_start is where this one began (0: power-on).
        std::uint64_t window = 0;
        std::uint64_t scan_start = 0;
        std::optional<std::uint64_t> last_hit;
        std::string reply;
    };
    std::optional<Replay> replay_;
    bool replay_requested_ = false;
    unsigned runs_ = 0;
};

}  // namespace avrbench
