// The temperatures a firmware was told to reach, from the G-code lines it
// accepted, and whether each heated part of the board has got there: a run
// that waits for the firmware to be done waits for its heaters too
// (Bench::still_going), and the report draws the targets.
//
// Which part a command heats (the same rule for both): M104/M109 S<t> the
// n-th part with a temperature that is not a bed (T<n>, default 0);
// M140/M190 S<t> the first whose name contains "bed". S0 turns a heater off:
// no target.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/Time.hpp"

namespace avrbench {

class Board;
class Part;

// The board's parts whose signals declare a "temperature" role, in board order.
std::vector<Part*> heated_parts(const Board& board);
// The part a heater command sets (nullptr: not such a command, or no such part).
Part* heated_part_for(const std::vector<Part*>& heated, const std::string& gcode_line, double* target_degC);

class HeatTargets {
public:
    // Settled: within this of the target (Marlin 1.x Configuration.h,
    // TEMP_HYSTERESIS 3: "range of +/- temperatures considered 'close' to
    // the target one")...
    static constexpr double kBand_degC = 3.0;
    // ... or no longer changing: less than this in the last kQuietWindow_s
    // (assumed: a heater its firmware drives holds it within tenths; one
    // still heating, even a slow bed at 0.2 degC/s, moves degrees).
    static constexpr double kQuiet_degC = 0.5;
    static constexpr double kQuietWindow_s = 10.0;

    explicit HeatTargets(const Board& board);

    // A line the firmware accepted, at `now_ps`; `quoted` names it for people.
    void accepted(const std::string& line, Picoseconds now_ps, const std::string& quoted);
    // Reads the temperatures (call between slices of a run).
    void sample(Picoseconds now_ps);
    // Whether a heated part has not yet settled at its target; with `why`,
    // one phrase per such part there: "hotend at 97.2 degC, heading for
    // 150 degC (line 1 'M104 S150')".
    bool unsettled(Picoseconds now_ps, std::vector<std::string>* why) const;
    bool any_target() const { return !targets_.empty(); }

private:
    struct Target {
        double degC = 0;
        Picoseconds since_ps = 0;
        std::string line;
    };
    double temperature_degC(const Part& part) const;

    std::vector<Part*> heated_;
    std::map<const Part*, Target> targets_;
    std::map<const Part*, std::deque<std::pair<Picoseconds, double>>> history_;
};

}  // namespace avrbench
