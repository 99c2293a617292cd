// A stepper driver on a linear axis (steps/mm, travel) or a rotary axis
// (steps/rev): port `drive` requires `steps` (a step_dir_driver's counted
// steps, or a stepper motor's rotor: any ShaftMotion); a linear
// axis provides `carriage` for limit switches. Tracks the commanded steps and the carriage position; driving
// the carriage into either end of travel is a finding (a crash), and the
// carriage stays at the end it hit, as a real one would.
#pragma once

#include <functional>
#include <vector>

#include "parts/Carriage.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ShaftMotion.hpp"

namespace avrbench {

class Axis final : public Part, public Carriage {
public:
    // What this part finds (`avrbench findings` lists every kind).
    static const FindingKind kAxisOutOfTravel;  // axis-out-of-travel
    static std::vector<ParamSpec> param_specs();

    Axis(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return rotary_ ? "rotary_axis" : "linear_axis"; }

    bool rotary() const { return rotary_; }
    const ShaftMotion& drive() const { return *driver_; }
    std::uint64_t steps() const { return driver_->steps_taken(); }
    // Net steps at the driver's configured resolution (signed).
    double position_steps() const;
    // Linear: carriage position in mm (0 .. travel). Rotary: degrees.
    double position_mm() const override { return static_cast<double>(carriage_256_) * metres_per_256_ * 1e3; }
    double position_deg() const;
    double travel_mm() const override { return travel_m_ * 1e3; }
    double step_mm() const override { return 1e3 / steps_per_unit_; }
    std::string summary() override;
    // Linear: whether the carriage, at the speed it made since the mark,
    // reaches an end of travel within `seconds` (a crash it has not had yet).
    void mark_pace() override;
    bool may_find_more_at_pace(double seconds) override;
    unsigned crashes() const { return crashes_; }

    void on_move(std::function<void(double position_m)> fn) override { move_listeners_.push_back(std::move(fn)); }

private:
    void connect_drive(ShaftMotion& driver);
    void on_step(int delta_256);
    void trace_position();

    ShaftMotion* driver_ = nullptr;
    bool rotary_;
    double steps_per_unit_ = 0;  // STEP pulses per metre (linear) or per revolution (rotary)
    double start_m_ = 0;
    double metres_per_256_ = 0;  // carriage travel per 1/256 full step (linear)
    double radians_per_256_ = 0;  // per 1/256 full step (rotary)
    double travel_m_ = 0;
    // Carriage position in 1/256 full steps from the lower end: an integer,
    // so millions of steps do not accumulate rounding.
    std::int64_t carriage_256_ = 0;
    std::int64_t travel_256_ = 0;
    // What position_mm shows (trace_deadband: reversals up to deadband_256_ are not traced).
    double trace_deadband_m_ = 0;
    std::int64_t deadband_256_ = 0;
    std::int64_t traced_256_ = 0;
    int traced_direction_ = 0;
    double angle_rad_ = 0;
    double stall_allowance_m_ = 0;
    std::int64_t stall_allowance_256_ = 0;
    std::int64_t pushed_256_ = 0;  // driven into the end since the carriage last moved freely
    std::int64_t pace_carriage_256_ = 0;  // at mark_pace()
    Cycle pace_cycle_ = 0;
    bool in_crash_ = false;
    unsigned crashes_ = 0;
    std::size_t sig_position_ = 0;
    std::vector<std::function<void(double)>> move_listeners_;
};

}  // namespace avrbench
