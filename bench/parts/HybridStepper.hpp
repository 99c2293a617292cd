// A two-phase hybrid stepper motor as a board part: the physics of
// HybridStepperModel, driven by
//   - an L293D bridge (bipolar, coil-driven: the firmware switches the bridge
//     inputs, directly or through a 74HC595),
//   - low-side switches (unipolar six-wire motor, centre taps to `supply`,
//     flyback diodes, one sense resistor per coil pair feeding an ADC channel),
//   - or a step/dir driver (its microstep current vector, ideal chopper).
//
// Outputs: rotor angle, commanded angle (from the excitation), following
// error, lost steps and stall events (findings), and traces of the phase
// currents, angle and speed. docs/MOTOR.md describes the model and its
// validation against seed 003.
//
// Time: the model is integrated lazily, from the last update to the cycle of
// each drive change, and on a periodic tick (`sample_period`) while it moves,
// so stalls are seen without pin edges. Never the wall clock.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "parts/HybridStepperModel.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ShaftMotion.hpp"
#include "parts/WindingDrive.hpp"

namespace avrbench {

class HybridStepper final : public Part, public ShaftMotion {
public:
    // What this part finds (`avrbench findings` lists every kind).
    static const FindingKind kMotorStall;  // motor-stall
    static std::vector<ParamSpec> param_specs(bool unipolar);
    static const std::map<std::string, std::map<std::string, std::string>>& presets();

    struct StallEvent {
        Cycle cycle;
        double commanded_deg, rotor_deg;
        double commanded_rpm;  // the excitation's speed when synchronism was lost
        long lost_steps;       // full steps lost so far (after this slip)
    };

    HybridStepper(std::string name, Mcu& clock, const ParamValues& params, bool unipolar);
    std::string_view type() const override { return unipolar_ ? "unipolar_stepper" : "hybrid_stepper"; }
    void start() override;
    std::string summary() override;
    // Turning since the mark: a stall depends on speed and load, which may change.
    void mark_pace() override { pace_shaft_steps_ = shaft_steps_; }
    bool may_find_more_at_pace(double seconds) override {
        (void)seconds;
        return shaft_steps_ != pace_shaft_steps_;
    }

    // Port `windings` requires what drives the windings (a DriveSource: the
    // motor knows the interface, not the parts); per winding (A, B; unipolar:
    // A, B, C = A-, D = B-) its tap on that source comes from phase_a/phase_b
    // or coil_a..coil_d. A unipolar motor provides its sense resistors'
    // voltages on analog ports `sense_ac` and `sense_bd`.
    std::size_t winding_count() const { return model_.winding_count(); }
    // Unipolar: the centre-tap supply and the sense resistor, for the switches' drives.
    double supply_v() const { return supply_v_; }
    double sense_ohm() const { return sense_ohm_; }

    // Brings the model up to the clock's present cycle.
    void sync();
    // Outputs, as of the last sync (call sync() first for "now").
    double angle_deg() const;
    double commanded_deg() const;
    double following_error_deg() const { return commanded_deg() - angle_deg(); }
    double speed_rpm() const;
    double phase_current(int phase) const { return model_.phase_current(phase); }
    // Full steps the rotor is behind its excitation, counted in whole pole
    // slips (4 full steps each); negative when ahead.
    long lost_steps() const { return 4 * slip_count_; }
    unsigned stalls() const { return stalls_; }
    std::uint64_t slips() const { return slips_total_; }
    bool energized() const { return have_command_; }
    // Voltage across the A/C (0) or B/D (1) sense resistor (unipolar).
    double sense_voltage(int pair) const;
    const HybridStepperModel& model() const { return model_; }

    void on_stall(std::function<void(const StallEvent&)> fn) { stall_listeners_.push_back(std::move(fn)); }

    // ShaftMotion (port `shaft`): the rotor, in full steps, for an axis such
    // as a lead screw's carriage; it follows the rotor (lag, slips and all),
    // updated at every drive change and sample tick while the rotor moves.
    unsigned configured_microsteps() const override { return 1; }
    std::int64_t position_256() const override { return shaft_256_; }
    void on_step(std::function<void(int delta_256)> fn) override { shaft_listeners_.push_back(std::move(fn)); }
    std::uint64_t steps_taken() const override { return shaft_steps_; }
    std::string motion_summary() const override;
    std::string rate_summary() const override { return ""; }

private:
    void connect_windings(DriveSource& source);
    void listen(DriveSource& source);
    void on_drive_change();
    void refresh_drive();
    void update_command_from_polarity();
    void set_command(double electrical);
    void check_slip();
    void arm_tick();
    void on_tick();
    void publish_all();
    void update_shaft();

    bool unipolar_;
    HybridStepperModel model_;
    double seconds_per_cycle_;
    Cycle sample_cycles_, release_cycles_, stall_quiet_cycles_, hold_trace_cycles_;
    // Tracing while holding (publish_all).
    Cycle last_traced_change_ = 0, last_trace_ = 0;
    double last_traced_command_ = 0;
    bool last_traced_stall_ = false, traced_once_ = false;
    Cycle last_cycle_ = 0;

    // What drives the windings, and one drive per winding.
    DriveSource* source_ = nullptr;
    bool angle_from_source_ = false;  // the source commands the angle (a step/dir driver)
    std::vector<WindingTap> taps_;
    double driver_offset_ = 0;  // 2*pi*m aligning the driver's angle with the rotor

    // Unipolar sense resistors.
    double supply_v_ = 0, sense_ohm_ = 0;

    // The commanded (electrical) angle, from the excitation.
    bool have_command_ = false;
    double command_e_ = 0;
    int latched_[2] = {0, 0};
    bool release_pending_[2] = {false, false};
    Cycle release_since_[2] = {0, 0};
    std::uint64_t release_generation_[2] = {0, 0};
    Cycle last_on_change_ = ~Cycle{0};
    Cycle last_command_change_ = 0, prev_command_change_ = 0;
    double last_command_delta_e_ = 0;

    // The shaft as an axis sees it.
    std::int64_t shaft_256_ = 0;
    std::int64_t shaft_full_ = 0;  // whole full steps, for steps_taken
    std::uint64_t shaft_steps_ = 0;
    std::uint64_t pace_shaft_steps_ = 0;  // at mark_pace()
    std::vector<std::function<void(int)>> shaft_listeners_;

    // Synchronism.
    long slip_count_ = 0;
    std::uint64_t slips_total_ = 0;
    unsigned stalls_ = 0;
    bool in_stall_ = false;
    Cycle last_slip_ = 0;
    std::vector<std::function<void(const StallEvent&)>> stall_listeners_;

    bool tick_armed_ = false;
    std::size_t sig_angle_, sig_command_, sig_error_, sig_speed_, sig_ia_, sig_ib_, sig_lost_, sig_stalled_;
    std::size_t sig_sense_[2] = {0, 0};
};

}  // namespace avrbench
