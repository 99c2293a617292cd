// A part-cooling fan on a MOSFET output (RAMPS D9), PWM-driven or on/off.
// Its speed follows the drive as a first-order lag (the rotor's inertia),
// solved exactly between gate edges; every sample interval the plant it cools
// gets the current speed (0..1), which raises the block's loss to ambient
// (ThermalPlant). Fault "stopped": a seized or unplugged fan, which spins down.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class ThermalBody;

class Fan final : public Part {
public:
    enum class Fault { None, Stopped };

    static std::vector<ParamSpec> param_specs();

    // Port `body` requires the thermal_plant it cools.
    Fan(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "fan"; }
    void start() override;

    double speed() const;   // 0..1 of full speed, now
    double rpm() const { return speed() * full_speed_rpm_; }
    std::uint64_t tach_edges() const { return tach_edges_; }
    bool driven() const { return driven_; }
    void inject(Fault fault, Cycle at_cycle);
    std::vector<std::string> fault_names() const override { return {"stopped"}; }

private:
    void connect_body(ThermalBody& body);
    void on_input(std::size_t pin, bool level) override;
    void apply_fault(const std::string& fault) override;
    void update();
    void settle_speed();
    void on_sample(Cycle scheduled);
    void on_tach(Cycle scheduled);
    void schedule_tach(Cycle from);
    void release_tach();

    ThermalBody* plant_ = nullptr;
    std::size_t pwm_pin_;
    bool active_level_;
    double tau_s_;
    bool stopped_ = false;
    bool driven_ = false;
    double speed_ = 0;      // at last_cycle_
    Cycle last_cycle_ = 0;
    Cycle sample_cycles_;
    std::size_t sig_speed_;
    std::size_t tach_pin_;
    double full_speed_rpm_;
    unsigned pulses_per_rev_;
    double tach_pullup_ohm_;
    bool tach_low_ = false;
    bool tach_running_ = false;
    std::uint64_t tach_edges_ = 0;
};

}  // namespace avrbench
