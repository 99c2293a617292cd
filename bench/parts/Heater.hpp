// A resistive heater (cartridge or bed) switched by a low-side MOSFET whose
// gate is an MCU pin: hardware PWM, soft PWM or bang-bang all arrive as gate
// edges. While on it dissipates P = V² R / (R + R_series)² (R_series: MOSFET
// on-resistance and wiring, 0 unless given) into its plant's node; the energy
// is integrated exactly between edges (in cycles of its clock).
//
// A hardware PWM the timer hands out as a periodic wave (periph/timer/PeriodicOutput
// .hpp; only while nobody records the heater's signals) heats with its mean
// power instead: the on-time is still counted exactly, but the plant sees
// P * duty. Accepted for periods up to kMaxAveragedPeriod_s = 2.5 ms (the
// Arduino core's 490 Hz and 976 Hz analogWrite PWM included): following each
// edge instead would add a ripple of at most P * T / C to the block, 40 W x
// 2.5 ms / 16.7 J/K = 6 mK on the E3D preset (the smallest heat capacity in
// ThermalPlant's presets), well below what a thermistor and a 10-bit ADC
// resolve (~0.3 K per count near 200 degC). Teacup's RAMPS bed at duty 0 is
// such a wave: a 62.5 ns spike every 16 us.
//
// Faults: "disconnected" (open heater circuit: no power whatever the gate),
// "stuck_on" (MOSFET failed short: full power whatever the gate).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "periph/timer/PeriodicOutput.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class ThermalBody;

class Heater final : public Part {
public:
    enum class Fault { None, Disconnected, StuckOn };

    static std::vector<ParamSpec> param_specs();
    static const std::map<std::string, std::map<std::string, std::string>>& presets();

    // Port `body` requires a thermal_plant's `body`.
    Heater(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "heater"; }
    void start() override;

    bool on() const { return waving_ ? gate_on_now() : on_; }
    // The gate is a periodic wave the heater follows with its mean power.
    bool follows_wave() const { return waving_; }
    double power_on_W() const { return power_on_W_; }  // dissipation while on
    double power_W() const { return on() ? power_on_W_ : 0.0; }
    // Energy dissipated since power-on (exact to the cycle), J.
    double energy_J() const;
    // Cycles spent on since power-on.
    Cycle on_cycles() const;

    void inject(Fault fault, Cycle at_cycle);
    std::vector<std::string> fault_names() const override { return {"disconnected", "stuck_on"}; }

private:
    void connect_body(ThermalBody& body, Part& plant);
    void on_input(std::size_t pin, bool level) override;
    bool begin_input_wave(std::size_t pin, const PeriodicWave& wave) override;
    void end_input_wave(std::size_t pin, Cycle at) override;
    // Cycles the heater is on in [a, b) while it follows the wave.
    Cycle wave_on_cycles(Cycle a, Cycle b) const;
    bool gate_on_now() const;
    void apply_fault(const std::string& fault) override;
    void update();
    void on_sample(Cycle scheduled);

    ThermalBody* plant_ = nullptr;
    std::string node_;
    int source_ = -1;
    std::size_t gate_pin_;
    std::size_t sig_on_ = 0, sig_duty_ = 0, sig_power_ = 0;
    bool gate_active_level_;
    double power_on_W_;
    Fault fault_state_ = Fault::None;
    bool on_ = false;
    Cycle on_since_ = 0;
    Cycle on_total_ = 0;           // completed on-intervals
    Cycle sample_cycles_;
    Cycle last_sample_ = 0;
    Cycle on_at_last_sample_ = 0;
    // The gate is a periodic wave the heater follows (never with a fault:
    // a fault ends the wave first, and no wave begins during one); on_ and
    // on_since_ mean nothing meanwhile.
    bool waving_ = false;
    PeriodicWave wave_;
    Cycle wave_from_ = 0;     // on-time up to here is in on_total_
};

}  // namespace avrbench
