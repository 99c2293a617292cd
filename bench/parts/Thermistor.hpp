// An NTC thermistor in a voltage divider on an ADC pin.
//
// Resistance from the bead temperature through the Steinhart–Hart equation
//     1/T = A + B ln R + C (ln R)³        (T in kelvin)
// with A, B, C fitted exactly through three datasheet points (or through
// points of the β equation R = R25·e^{β(1/T − 1/T25)} for β-specified parts).
// The divider: "lower" leg (RAMPS 1.4, seed 001): pull-up from the reference
// to the pin, NTC from the pin to GND, V = Vref·R/(R + R_pullup); "upper":
// NTC from the reference to the pin, fixed resistor to GND. The voltage at
// the moment a conversion starts goes to the MCU's ADC (periph/adc/Adc.hpp), which
// quantises it; optional Gaussian noise from a seeded generator.
//
// Faults: "open" (broken wire: R = ∞), "shorted" (R = 0), "detached" (the
// bead fell out of the block and follows ambient while the block heats).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/TraceThrottle.hpp"

namespace avrbench {

class ThermalBody;

// The Steinhart–Hart curve of one NTC part.
struct NtcCurve {
    double a = 0, b = 0, c = 0;
    // Exact fit through three (degC, ohm) points.
    static NtcCurve fit(const std::array<std::pair<double, double>, 3>& points);
    // The β model through (t25_degC, r25) as three points at 25, 150, 250 degC.
    static NtcCurve from_beta(double r25_ohm, double t25_degC, double beta_K);
    double resistance_ohm(double degC) const;
    double temperature_degC(double ohm) const;
};

class Thermistor final : public Part {
public:
    enum class Fault { None, Open, Shorted, Detached };

    static std::vector<ParamSpec> param_specs();
    static const std::map<std::string, std::map<std::string, std::string>>& presets();

    // Port `body` requires the thermal_plant whose sensor node it is; port
    // `out` provides the divider's voltage (a net joins it to an ADC pin of
    // `clock`, the MCU that samples it).
    Thermistor(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "thermistor"; }

    const NtcCurve& curve() const { return curve_; }
    // The divider's output for a bead temperature, without noise or faults.
    double divider_volts(double degC) const;
    double divider_volts_for_resistance(double ohm) const;
    // What the pin shows now (advances the plant; no noise).
    double volts_now();
    std::uint64_t samples() const { return samples_; }

    void inject(Fault fault, Cycle at_cycle);
    std::vector<std::string> fault_names() const override { return {"open", "shorted", "detached"}; }

private:
    void connect_body(ThermalBody& body);
    double sample(Cycle cycle);
    double gaussian();
    void apply_fault(const std::string& fault) override;

    ThermalBody* plant_ = nullptr;
    NtcCurve curve_;
    bool lower_leg_;
    double fixed_ohm_, reference_v_, noise_v_;
    std::mt19937_64 rng_;
    Fault fault_state_ = Fault::None;
    std::uint64_t samples_ = 0;
    TraceThrottle trace_;
    std::size_t sig_temperature_ = 0, sig_volts_ = 0;
};

}  // namespace avrbench
