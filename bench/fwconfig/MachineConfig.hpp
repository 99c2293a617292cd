// What a firmware's configuration says about the machine it drives, in the
// bench's terms, each fact with the configuration line it came from: read
// from Marlin/Prusa/Sprinter, Repetier, Teacup, grbl and Klipper
// configurations (fwconfig/ConfigReaders.hpp) and written as a board that
// extends a standard one (fwconfig/BoardFromConfig.hpp).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace avrbench {

template <class T>
struct Sourced {
    T value;
    std::string source;  // "Configuration.h:612: DEFAULT_AXIS_STEPS_PER_UNIT {80, 80, 4000, 500}"
};

// How the firmware reads an end switch: which level means triggered, and
// whether it turns the MCU's pull-up on (without one, the switch must drive
// both levels: an optical or hall endstop).
struct EndstopLogic {
    bool triggered_high = true;
    bool pull_up = true;
};

struct AxisConfig {
    std::optional<Sourced<double>> steps_per_mm;      // at the firmware's microstepping
    std::optional<Sourced<bool>> dir_high_is_plus;    // DIR level the firmware drives for a + move
    std::optional<Sourced<bool>> enable_high;         // the driver enable's active level
    std::optional<Sourced<int>> microsteps;
    std::optional<Sourced<double>> min_mm, max_mm;    // the firmware's range of positions
    std::optional<Sourced<int>> home_dir;             // -1: homes to min, +1: to max
    std::optional<Sourced<EndstopLogic>> min_switch, max_switch;
    std::optional<Sourced<int>> stall_sgt;            // a TMC2130's tuned stallGuard threshold
};

struct MachineConfig {
    std::string firmware;                    // "Marlin", "grbl", ...
    std::optional<Sourced<std::string>> base_board;  // the standard board the firmware's board setting names
    std::string base_unknown;                // else why not ("MOTHERBOARD BOARD_ULTIMAKER: no standard board")
    std::array<AxisConfig, 3> axes;          // X, Y, Z
    std::optional<Sourced<double>> e_steps_per_mm;
    std::optional<Sourced<bool>> soft_min, soft_max;  // software endstops on
    // The sensors' presets: a thermistor's, or "ad595" (a thermocouple_amplifier).
    std::optional<Sourced<std::string>> hotend_thermistor, bed_thermistor;
    // Set when the firmware's G28 does not end at its 0 (Marlin's
    // Z_SAFE_HOMING parks over the bed): the oracle is given no home, so a
    // G28 ends the judging, said in the summary.
    std::optional<std::string> homing_not_judged;
    std::vector<std::string> not_mapped;     // "file:line: what, and why"
};

}  // namespace avrbench
