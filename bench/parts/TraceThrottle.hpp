// At most one trace value per interval for a part sampled on demand (a
// sensor the ADC reads at every conversion, thousands of times a second):
// the first sample is recorded, then one at least `interval` after the last.
#pragma once

#include <algorithm>
#include <string>

#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"

namespace avrbench {

class TraceThrottle {
public:
    // `where` prefixes the error for an interval that is not positive ("part 'x': ").
    TraceThrottle(const Mcu& clock, double interval_s, const std::string& where) {
        if (!(interval_s > 0)) throw BadInput(where + "sample_interval must be positive");
        every_ = std::max<Cycle>(1, clock.cycles_from_seconds(interval_s));
    }
    // True when a sample at `now` is to be recorded (and it counts as recorded).
    bool due(Cycle now) {
        if (recorded_once_ && now - last_ < every_) return false;
        recorded_once_ = true;
        last_ = now;
        return true;
    }

private:
    Cycle every_ = 1;
    Cycle last_ = 0;
    bool recorded_once_ = false;
};

}  // namespace avrbench
