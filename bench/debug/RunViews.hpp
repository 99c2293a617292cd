// What `monitor` shows of a run besides the MCU the debugger stops: the
// board's nets and parts (axis positions, temperatures: every signal a part
// declares), the MCU's pins, the host's last lines and the timeline's last
// events. One view per kind of run (run/BoardRun, run/McuRun).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "debug/Debugger.hpp"

namespace avrbench {

class Bench;
class McuRun;
class UartHost;

// `host`: the job's host for `monitor uart` (nullptr: none).
DebugRunView board_debug_view(Bench& bench, const UartHost* host, bool replayable);
DebugRunView mcu_debug_view(McuRun& run);

// A front end's --gdb [MCU=]PORT items and --break-at-finding, --break-at
// TIME and --break-at-cycle N as the debugger's options; nullopt without
// --gdb (BadInput for a --break-at option without it, or a bad item).
struct DebugArgs {
    std::vector<std::string> gdb;
    bool break_at_finding = false;
    std::string break_at, break_at_cycle;
};
std::optional<DebugOptions> debug_options(const DebugArgs& args);

}  // namespace avrbench
