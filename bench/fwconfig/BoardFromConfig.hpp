// A board file from a firmware's configuration: it `extends:` the standard
// board the configuration names (or the one given) and declares again, with
// the configuration's values, the parts they change - each axis' steps/mm
// and travel, its driver's direction, enable level and microstepping, its
// end switches' logic, side and place, the motion oracle's frame (where
// homing puts 0, the software endstops), the hot end's filament steps and
// the thermistors - every value with the configuration line it came from in
// a comment, and what it could not map listed at the end.
//
// The geometry: a switch sits `inset` inside its end of travel (the standard
// board's, 2 mm on RAMPS), the firmware's range of positions [min, max]
// between the switches, so the travel is max - min + 2 * inset and the
// carriage starts in the middle of it.
#pragma once

#include <string>
#include <vector>

#include "boards/BoardFile.hpp"
#include "fwconfig/MachineConfig.hpp"

namespace avrbench {

struct BoardFromConfigOptions {
    std::string name;                 // the generated board's name
    std::vector<std::string> inputs;  // the configuration files, for the header
    std::string base;                 // a standard board or file; empty: the configuration's
};

std::string board_from_config(const MachineConfig& config, const BoardFromConfigOptions& options);

}  // namespace avrbench
