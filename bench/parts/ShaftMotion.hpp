// What an axis (or an extruder's filament feed) follows: a shaft that turns
// in steps. A step/dir driver's counted steps are one; a stepper motor's
// rotor, which can lag, slip or be pushed, is another.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "parts/PortType.hpp"

namespace avrbench {

class ShaftMotion {
public:
    static constexpr PortType kPort{"steps", "a step_dir_driver's steps"};
    virtual ~ShaftMotion() = default;
    // The step an axis' steps_per_mm counts, in microsteps per full step
    // (a driver's configured resolution; 1 for a motor's full steps).
    virtual unsigned configured_microsteps() const = 0;
    // Shaft position in 1/256 full steps, signed.
    virtual std::int64_t position_256() const = 0;
    // Called with the change in 1/256 full steps whenever the shaft moved.
    virtual void on_step(std::function<void(int delta_256)> fn) = 0;
    // Steps the shaft took (a driver: accepted STEP edges; a motor: full
    // steps its rotor crossed, either way).
    virtual std::uint64_t steps_taken() const = 0;
    // Clauses for an axis' summary line: after the axis name (the steps) and
    // at the end (their rate; may be empty).
    virtual std::string motion_summary() const = 0;
    virtual std::string rate_summary() const = 0;
};

}  // namespace avrbench
