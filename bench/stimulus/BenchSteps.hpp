// The stimulus a scenario applies, as typed steps: what a person does at the
// bench, in order. Scenario files (verify/Scenario.hpp) parse and check them
// when the file loads; verify/ScenarioRun.cpp carries them out on a board.
#pragma once

#include <string>
#include <vector>
#include <variant>

#include "core/Time.hpp"

namespace avrbench {

struct SendStep { std::string line; };                 // one line through the serial host
struct SendFileStep { std::string path; };             // a job, with the port's flow control
struct DelayStep { Picoseconds duration_ps = 0; };
struct WaitIdleStep { Picoseconds settle_ps = 0; };    // hosts finished, no STEP edge for settle
struct WaitForTextStep { std::string text; };          // a firmware line containing it
struct WaitPinStep { std::string pin; bool level = false; };
struct SetInputStep { std::string pin; bool level = false; };
struct ReleaseInputStep { std::string pin; };
struct InjectFaultStep { std::string part; std::string fault; };
struct PartActionStep { std::string part; std::string action; std::vector<double> arguments; };  // press a knob, turn it

using StepAction = std::variant<SendStep, SendFileStep, DelayStep, WaitIdleStep, WaitForTextStep, WaitPinStep,
                                SetInputStep, ReleaseInputStep, InjectFaultStep, PartActionStep>;

}  // namespace avrbench
