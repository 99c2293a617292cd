// An RC hobby servo: the width of each pulse on its signal pin (typically
// 50 Hz frames) commands an angle through a calibration table, and the horn
// slews there at a limited rate within the table's range. Pulses that differ
// from the last accepted one by less than the dead band are ignored, as the
// servo's amplifier does; pulses outside the table's range are clamped to it
// and reported (servo-pulse-out-of-range, once per spell).
#pragma once

#include <cstdint>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ServoHorn.hpp"

namespace avrbench {

class RcServo final : public Part, public ServoHorn {
public:
    // What this part finds (`avrbench findings` lists every kind).
    static const FindingKind kServoPulseOutOfRange;  // servo-pulse-out-of-range
    static std::vector<ParamSpec> param_specs();

    RcServo(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "rc_servo"; }
    std::string summary() override;

    // The horn's angle now, in degrees of the calibration table.
    double angle_deg() const override;
    double target_deg() const { return target_deg_; }
    double last_pulse_us() const { return last_pulse_us_; }
    unsigned pulses() const { return pulses_; }
    // The horn's travel: the calibration table's first and last angle.
    double min_angle_deg() const override { return table_.front().deg; }
    double max_angle_deg() const override { return table_.back().deg; }
    // The table's angle for a pulse width (clamped to the table's ends).
    double angle_for_pulse_us(double width_us) const;

private:
    struct Point {
        double deg;
        double us;
    };
    void on_input(std::size_t pin, bool level) override;
    void on_pulse(double width_us, Cycle end);
    double angle_at(Cycle cycle) const;

    std::size_t signal_pin_;
    std::vector<Point> table_;  // ascending in both columns
    double slew_deg_per_s_;
    double dead_band_us_;
    double min_pulse_us_, max_pulse_us_;  // shorter or longer is not a command
    Cycle rise_cycle_ = 0;
    bool high_ = false;
    double from_deg_, target_deg_;  // the motion under way: from, to
    Cycle motion_start_ = 0;
    double accepted_us_ = -1;  // the last pulse that moved the target
    double last_pulse_us_ = 0;
    unsigned pulses_ = 0;
    bool out_of_range_ = false;
    std::uint64_t arrival_generation_ = 0;
    std::size_t sig_angle_, sig_target_, sig_pulse_;
};

}  // namespace avrbench
