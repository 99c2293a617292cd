// A long interactive run's state while it goes on (a klippy or OctoPrint
// session on --pty), so a person can watch it without ending it: the
// simulated and wall time, each axis' position and steps, each thermal
// body's temperature, the host job's progress and the findings so far - as
// one line, and as JSON for a program (the file --status-file rewrites).
#pragma once

#include <string>

namespace avrbench {

class Bench;
class UartHost;

struct LiveStatus {
    std::string line;  // "status 12.000 s (wall 12.1 s): x 10.000 mm (800 steps), ..., findings 0"
    std::string json;  // {"simulated_s": 12.0, "wall_s": 12.1, "axes": {...}, "temperatures_degC": {...}, ...}
};

// `job`: the run's G-code host, if it has one.
LiveStatus live_status(Bench& bench, const UartHost* job, double wall_s);

}  // namespace avrbench
