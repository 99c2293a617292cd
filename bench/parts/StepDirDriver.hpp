// A step/dir stepper driver (A4988, DRV8825, TMC2208 in legacy step/dir mode,
// or generic). Watches STEP, DIR, ENABLE and the microstep pins, counts steps
// into a position, and reports every violation of the datasheet timing as a
// finding with its cycle.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ShaftMotion.hpp"
#include "parts/WindingDrive.hpp"

namespace avrbench {

class StepDirDriver final : public Part, public DriveSource, public ShaftMotion {
public:
    // What this part finds (`avrbench findings` lists every kind).
    static const FindingKind kStepHighTooShort;  // step-high-too-short
    static const FindingKind kStepLowTooShort;  // step-low-too-short
    static const FindingKind kDirSetupViolation;  // dir-setup-violation
    static const FindingKind kDirHoldViolation;  // dir-hold-violation
    static const FindingKind kStepRateTooHigh;  // step-rate-too-high
    static std::vector<ParamSpec> param_specs();
    // Datasheet timing per preset (name -> parameter -> value with unit).
    static const std::map<std::string, std::map<std::string, std::string>>& presets();

    StepDirDriver(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "step_dir_driver"; }

    // Position in 1/256 full steps (the common denominator of every microstep
    // resolution the presets support), signed; + is DIR at its "forward" level.
    std::int64_t position_256() const override { return position_256_; }
    std::uint64_t steps_taken() const override { return steps_taken_; }        // active edges while enabled
    std::uint64_t steps_ignored() const { return steps_ignored_; }    // active edges while disabled
    double peak_step_rate_hz() const { return peak_step_rate_hz_; }   // from the shortest STEP period
    unsigned microsteps() const { return current_microsteps_; }       // resolution at the last step
    unsigned configured_microsteps() const override { return configured_microsteps_; }
    bool enabled() const;
    void start() override;

    // Called after every step that moved the position (the axis listens).
    void on_step(std::function<void(int delta_256)> fn) override { step_listeners_.push_back(std::move(fn)); }
    std::string motion_summary() const override;
    std::string rate_summary() const override;

    // The winding currents, for a motor part driven by this driver (taken as
    // an ideal chopper at the set current). The A4988's and DRV8825's
    // microstep tables start at their home state, 45 electrical degrees
    // (70.7 % on both windings; taken the same for the TMC2208), and advance
    // 90 degrees per full step, so the present
    // microstep's electrical angle is 45 deg + position_256 * 90 deg / 256 and
    // the currents are current * (cos, sin) of it.
    double electrical_angle() const {
        return 0.7853981633974483 + static_cast<double>(position_256_) * (1.5707963267948966 / 256);
    }
    double set_current_a() const { return current_a_; }
    double motor_supply_v() const { return motor_supply_v_; }

    // DriveSource: the motor is told after every step and ENABLE change.
    bool commands_angle() const override { return true; }
    double commanded_electrical_angle() const override { return electrical_angle(); }
    bool outputs_enabled() const override { return enabled(); }
    // Winding 0 (A) or 1 (B): the chopper's current while enabled; disabled,
    // the current decays through the output MOSFETs' body diodes into the supply.
    WindingDrive winding(int k) const;
    WindingDrive winding_at(const WindingTap& tap) const override { return winding(tap.phase); }
    std::string tap_problem(const WindingTap& tap) const override;

private:
    void on_input(std::size_t pin, bool level) override;
    void on_step_edge(bool active);
    void on_dir_change();
    unsigned microsteps_from_pins() const;
    Cycle cycles(double seconds) const;

    std::size_t step_pin_, dir_pin_, enable_pin_;
    std::vector<std::size_t> ms_pins_;
    std::string preset_;

    bool step_active_level_;         // true: rising edge steps
    bool enable_active_level_;       // level of ENABLE that enables the outputs
    bool forward_dir_level_;         // DIR level counted as + (the "positive" direction)
    Cycle step_high_min_cycles_, step_low_min_cycles_, dir_setup_cycles_, dir_hold_cycles_;
    Cycle min_step_period_cycles_;
    double max_step_rate_hz_;
    unsigned configured_microsteps_;  // when the MS pins are not wired (jumpers)
    unsigned current_microsteps_;

    std::int64_t position_256_ = 0;
    std::uint64_t steps_taken_ = 0, steps_ignored_ = 0;
    double peak_step_rate_hz_ = 0;
    bool have_active_edge_ = false, have_inactive_edge_ = false, have_dir_change_ = false;
    Cycle last_active_edge_ = 0, last_inactive_edge_ = 0, last_dir_change_ = 0;
    std::size_t sig_step_, sig_dir_, sig_position_, sig_enabled_;
    std::vector<std::function<void(int)>> step_listeners_;
    double current_a_, motor_supply_v_;
};

}  // namespace avrbench
