// What `monitor` shows of a run besides the MCU the debugger stops: the
// board's nets and parts (axis positions, temperatures: every signal a part
// declares), the MCU's pins, the host's last lines and the timeline's last
// events. One view per kind of run (verify/BoardRun, verify/McuRun).
#pragma once

#include <string>
#include <vector>

#include "debug/Debugger.hpp"

namespace avrbench {

class BoardRun;
class McuRun;

DebugRunView board_debug_view(BoardRun& run, bool replayable);
DebugRunView mcu_debug_view(McuRun& run);

// "--gdb [MCU=]PORT" items as ports (BadInput naming the item).
std::vector<DebugOptions::Port> parse_gdb_ports(const std::vector<std::string>& items);

}  // namespace avrbench
