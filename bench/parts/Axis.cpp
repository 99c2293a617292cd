#include "parts/Axis.hpp"

#include "parts/PartRegistry.hpp"

#include <cmath>
#include <cstdio>

#include "core/Errors.hpp"

namespace avrbench {

namespace {

// linear_axis and rotary_axis: one model; the type name fixes its kind.
PartType axis_type(const std::string& kind) {
    PartType t = simple_part_type<Axis>(kind + "_axis");
    t.implied = {{"kind", kind}};
    return t;
}

}  // namespace

REGISTER_PART_TYPE(axis_type("linear"));
REGISTER_PART_TYPE(axis_type("rotary"));

const FindingKind Axis::kAxisOutOfTravel = FindingKind::declare("axis-out-of-travel", "an axis was driven past either end of its travel (a crash)", Severity::Warning);

std::vector<ParamSpec> Axis::param_specs() {
    using PT = ParamType;
    return {
        {.name = "kind", .type = PT::Choice, .default_value = "linear", .choices = {"linear", "rotary"}},
        // 1e-3..1e6: a 1 mm lead screw at 1/256 of 200 steps is 51 200 steps/mm.
        {.name = "steps_per_mm", .type = PT::Quantity,
         .help = "STEP pulses per mm at the driver's configured microsteps (linear)", .min = 1e-3, .max = 1e6},
        {.name = "steps_per_rev", .type = PT::Quantity,
         .help = "STEP pulses per revolution at the driver's configured microsteps (rotary)", .min = 1, .max = 1e7},
        {.name = "travel", .type = PT::Quantity, .dimension = Dimension::Length,
         .help = "length of travel (linear), from 0"},
        {.name = "start_position", .type = PT::Quantity, .dimension = Dimension::Length, .default_value = "0mm",
         .source = "assumed: the carriage starts at 0", .help = "carriage position at power-on"},
        {.name = "trace_deadband", .type = PT::Quantity, .dimension = Dimension::Length, .default_value = "0mm",
         .source = "0: every change traced; a board whose rotors dither under a chopper sets a fraction of a step",
         .help = "a reversal of the carriage up to this far is not traced in position_mm (linear); switches and "
                 "judges still follow every 1/256 step",
         .min = 0, .max = 1e-3},
        {.name = "stall_allowance", .type = PT::Quantity, .dimension = Dimension::Length, .default_value = "0mm",
         .source = "0: any step past an end is a crash; an axis homed sensorless against its frame sets what its "
                   "motor may slip there, e.g. 4 full steps (a stalled two-phase motor slips by whole electrical "
                   "periods of 4 full steps)",
         .help = "how far the driver may push the carriage into an end of travel (the motor stalling against the "
                 "frame) before it is an axis-out-of-travel finding (linear)",
         .min = 0, .max = 0.1},
    };
}

Axis::Axis(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock), rotary_(params.text("kind") == "rotary") {
    if (rotary_) {
        if (!params.has("steps_per_rev")) throw part_error(this->name(), "a rotary axis needs steps_per_rev");
        const double steps_per_rev = params.quantity("steps_per_rev");
        // A 1.8 deg motor at 256 microsteps makes 51200 steps/rev; 1e7 covers any gearing.
        if (!(steps_per_rev > 0 && steps_per_rev <= 1e7)) {
            throw part_error(this->name(), "steps_per_rev must be above 0 and at most 1e7");
        }
        steps_per_unit_ = steps_per_rev;
    } else {
        if (!params.has("steps_per_mm")) throw part_error(this->name(), "a linear axis needs steps_per_mm");
        if (!params.has("travel")) throw part_error(this->name(), "a linear axis needs travel");
        // Ranges real machines span with room: lead screws at 256 microsteps
        // reach a few thousand steps/mm; no bench axis is longer than 100 m.
        const double steps_per_mm = params.quantity("steps_per_mm");
        if (!(steps_per_mm >= 1e-3 && steps_per_mm <= 1e6)) {
            throw part_error(this->name(), "steps_per_mm must be from 0.001 to 1e6");
        }
        if (!(params.quantity("travel") > 0 && params.quantity("travel") <= 100)) {
            throw part_error(this->name(), "travel must be longer than 0 and at most 100 m");
        }
        steps_per_unit_ = steps_per_mm * 1e3;
        travel_m_ = params.quantity("travel");
        start_m_ = params.quantity("start_position");
        trace_deadband_m_ = params.quantity("trace_deadband");
        stall_allowance_m_ = params.quantity("stall_allowance");
        if (start_m_ < 0 || start_m_ > travel_m_) {
            throw part_error(this->name(), "start_position outside 0..travel");
        }
        provide_port<Carriage>("carriage", *this, "the carriage position limit switches watch");
    }
    require_port<ShaftMotion>("drive", true, "a step_dir_driver's steps or a stepper motor's shaft",
                              [this](ShaftMotion& driver) { connect_drive(driver); });
}

void Axis::connect_drive(ShaftMotion& driver) {
    driver_ = &driver;
    // Steps are counted in 1/256 full steps: one is (256 / microsteps)^-1 of a configured step.
    const double microsteps = driver_->configured_microsteps();
    if (rotary_) {
        radians_per_256_ = 2.0 * 3.14159265358979323846 / steps_per_unit_ * microsteps / 256.0;
    } else {
        metres_per_256_ = microsteps / 256.0 / steps_per_unit_;
        travel_256_ = static_cast<std::int64_t>(std::floor(travel_m_ / metres_per_256_ + 1e-9));
        carriage_256_ = std::llround(start_m_ / metres_per_256_);
        traced_256_ = carriage_256_;
        deadband_256_ = static_cast<std::int64_t>(std::floor(trace_deadband_m_ / metres_per_256_ + 1e-9));
        stall_allowance_256_ = static_cast<std::int64_t>(std::floor(stall_allowance_m_ / metres_per_256_ + 1e-9));
    }
    // STEP pulses the driver took, and the net position in steps (signed).
    add_readout("steps", [this] { return driver_ != nullptr ? static_cast<double>(driver_->steps_taken()) : 0.0; });
    add_readout("position_steps", [this] { return driver_ != nullptr ? position_steps() : 0.0; });
    sig_position_ = add_signal({rotary_ ? "angle_deg" : "position_mm", true, rotary_ ? "deg" : "mm", "position", ""},
                               rotary_ ? 0.0 : position_mm());
    driver_->on_step([this](int delta) { on_step(delta); });
}

std::string Axis::summary() {
    char line[240];
    if (rotary_) {
        std::snprintf(line, sizeof line, "axis %-5s %s, %.3f deg%s", name().c_str(), driver_->motion_summary().c_str(),
                      position_deg(), driver_->rate_summary().c_str());
    } else {
        std::snprintf(line, sizeof line, "axis %-5s %s, at %.4f mm%s", name().c_str(), driver_->motion_summary().c_str(),
                      position_mm(), driver_->rate_summary().c_str());
    }
    return line;
}

void Axis::mark_pace() {
    pace_carriage_256_ = carriage_256_;
    pace_cycle_ = clock().cycle();
}

bool Axis::may_find_more_at_pace(double seconds) {
    if (rotary_ || in_crash_) return false;  // no ends; or at one, its crash told
    const Cycle elapsed = clock().cycle() - pace_cycle_;
    if (elapsed == 0) return true;  // no pace seen yet: cannot tell
    const double per_second = static_cast<double>(carriage_256_ - pace_carriage_256_) *
                              static_cast<double>(clock().frequency_hz()) / static_cast<double>(elapsed);
    const double ahead = static_cast<double>(carriage_256_) + per_second * seconds;
    return ahead < 0.0 || ahead > static_cast<double>(travel_256_);
}

double Axis::position_steps() const {
    return static_cast<double>(driver_->position_256()) * driver_->configured_microsteps() / 256.0;
}

double Axis::position_deg() const { return angle_rad_ * 180.0 / 3.14159265358979323846; }

void Axis::on_step(int delta_256) {
    if (rotary_) {
        angle_rad_ += delta_256 * radians_per_256_;
        publish(sig_position_, position_deg());
        for (auto& fn : move_listeners_) fn(angle_rad_);
        return;
    }
    const std::int64_t wanted = carriage_256_ + delta_256;
    if (wanted < 0 || wanted > travel_256_) {
        // The steps a stalled motor loses against the frame add up; within
        // the allowance they are sensorless homing, past it a crash.
        pushed_256_ += wanted < 0 ? -wanted : wanted - travel_256_;
        if (!in_crash_ && pushed_256_ > stall_allowance_256_) {
            in_crash_ = true;
            ++crashes_;
            char detail[200];
            const double end_mm = wanted < 0 ? 0.0 : travel_m_ * 1e3;
            const double pushed_mm = static_cast<double>(pushed_256_) * metres_per_256_ * 1e3;
            if (stall_allowance_256_ == 0) {
                std::snprintf(detail, sizeof detail, "carriage driven past the %s end of travel (%.4f mm of 0..%.3f mm)",
                              wanted < 0 ? "lower" : "upper", wanted < 0 ? -pushed_mm : end_mm + pushed_mm,
                              travel_m_ * 1e3);
            } else {
                std::snprintf(detail, sizeof detail,
                              "carriage driven %.4f mm into the %s end of travel (stall allowance %.4f mm)", pushed_mm,
                              wanted < 0 ? "lower" : "upper", stall_allowance_m_ * 1e3);
            }
            report(Axis::kAxisOutOfTravel, detail);
        }
        carriage_256_ = wanted < 0 ? 0 : travel_256_;  // the carriage stays at the end it hit
    } else {
        in_crash_ = false;
        pushed_256_ = 0;
        carriage_256_ = wanted;
    }
    trace_position();
    const double position_m = static_cast<double>(carriage_256_) * metres_per_256_;
    for (auto& fn : move_listeners_) fn(position_m);
}

// The traced position follows the carriage on and on in the direction it
// last went; a turn back is traced once it passes the dead band, so a rotor
// dithering between two 1/256 steps under a chopper is one change, not
// thousands a second (the published value is then at most the dead band off).
void Axis::trace_position() {
    const std::int64_t change = carriage_256_ - traced_256_;
    if (deadband_256_ > 0) {
        if (change == 0) return;
        const int direction = change > 0 ? 1 : -1;
        if (direction != traced_direction_ && (change > 0 ? change : -change) <= deadband_256_) return;
        traced_direction_ = direction;
    }
    traced_256_ = carriage_256_;
    publish(sig_position_, position_mm());
}

}  // namespace avrbench
