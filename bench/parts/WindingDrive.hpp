// The electrical interface between a motor winding and what drives it (an
// L293D half-bridge pair, a low-side switch with its flyback diode, or a
// step/dir driver's chopper). Bridge outputs are not logic levels: a bridge
// part describes, per winding, the terminal voltage it imposes for each
// direction of the winding current, and the motor part asks for it by
// reference whenever the bridge's inputs change.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "parts/PortType.hpp"

namespace avrbench {

// What one winding sees. The current i is positive from the winding's first
// terminal to its second (for a bipolar phase: from the bridge output wired to
// "+" to the one wired to "-").
//  - Voltage mode: while i > 0 the terminal voltage is v_pos - r_pos*i, while
//    i < 0 it is v_neg - r_neg*i (transistor saturation or clamp diodes, with
//    the direction-dependent drops). At i == 0 the current starts only if the
//    circuit can push it against the back-EMF e: v_pos > e (then i > 0) or
//    v_neg < e (then i < 0); otherwise it stays 0 (every path is blocked by a
//    diode: an open half-bridge, a switch that is off). v_pos <= v_neg always
//    holds for passive circuits; v_neg = +inf means "no path for i < 0".
//  - Current mode (a step/dir driver's chopper, taken as ideal): the driver
//    holds i at `target_a`, slewing with the tracking time constant of the
//    motor part but never applying more than +-supply_v across the winding.
struct WindingDrive {
    static constexpr double kNoPath = std::numeric_limits<double>::infinity();

    bool current_mode = false;
    double v_pos = 0, v_neg = 0;  // V
    double r_pos = 0, r_neg = 0;  // ohm, in series with the winding while conducting that way
    double target_a = 0;          // current mode: A
    double supply_v = 0;          // current mode: the driver's motor supply
    // The excitation the firmware asked for, for the commanded angle: +1 the
    // winding is driven forward, -1 reverse, 0 not driven (off, braking,
    // outputs disabled). Not used by the physics.
    int polarity = 0;

    // An open winding: no current in either direction (both diodes blocked).
    static WindingDrive open() {
        WindingDrive d;
        d.v_pos = -kNoPath;
        d.v_neg = kNoPath;
        return d;
    }
};

// Where one winding of a motor is wired on the part that drives it, as the
// motor's board entry says: a bridge's outputs (`plus`, `minus`: 1..4 on an
// L293D), a low-side switch's channel (`minus`; the winding's other end is
// the centre tap at `supply_v`, with `series_ohm` more in the switched path,
// a sense resistor), or a step/dir driver's phase (`phase`: 0 = A, 1 = B).
struct WindingTap {
    int phase = 0;
    int plus = 0, minus = 0;
    double supply_v = 0, series_ohm = 0;
};

// A part whose outputs drive windings. Listeners are called after every
// change of the drive state, at the cycle of the change; a motor integrates up
// to that cycle with the drive it had, then asks for the new one.
class DriveSource {
public:
    static constexpr PortType kPort{"windings", "an l293d's windings"};
    virtual ~DriveSource() = default;
    void on_drive_change(std::function<void()> fn) { drive_listeners_.push_back(std::move(fn)); }

    // A driver that sets the electrical angle itself (a step/dir driver's
    // microstep table) reports it, and the motor follows it; for a bridge or
    // switches the motor infers the command from which windings are driven.
    virtual bool commands_angle() const { return false; }
    virtual double commanded_electrical_angle() const { return 0; }
    // Outputs switched on (a driver's ENABLE); a bridge or a switch always is.
    virtual bool outputs_enabled() const { return true; }

    // The drive a winding wired at `tap` sees now.
    virtual WindingDrive winding_at(const WindingTap& tap) const = 0;
    // Why `tap` names outputs this part does not have ("" when it fits).
    virtual std::string tap_problem(const WindingTap& tap) const = 0;

protected:
    void notify_drive_change() {
        for (auto& fn : drive_listeners_) fn();
    }

private:
    std::vector<std::function<void()>> drive_listeners_;
};

}  // namespace avrbench
