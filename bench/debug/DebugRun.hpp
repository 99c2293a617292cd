// A run under the debugger, the way every front end makes one: runs of the
// same options until one ends without asking for a replay (reverse
// execution), then the debuggers hear that the program ended. The run that
// ended is returned for its summary and verdict.
#pragma once

#include <memory>

#include "debug/Debugger.hpp"
#include "run/BoardRun.hpp"
#include "run/McuRun.hpp"

namespace avrbench {

std::unique_ptr<BoardRun> run_board_debugged(const BoardRunOptions& options, Debugger& debugger);
std::unique_ptr<McuRun> run_mcu_debugged(const McuRunOptions& options, Debugger& debugger);

// A debugged run's verdict: a debugger that killed the program interrupted it.
RunVerdict debugged_verdict(const Debugger& debugger, RunVerdict verdict);

}  // namespace avrbench
