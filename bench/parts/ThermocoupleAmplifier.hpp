// A thermocouple on a cold-junction-compensated amplifier (AD595) whose
// output an ADC pin samples: V = gain × T, clamped to the supply.
//
// AD594/AD595 datasheet (Analog Devices, rev. C): "a high level (10 mV/°C)
// output directly from a thermocouple signal", single +5 V supply for 0 °C
// upwards (so 0 .. 500 °C before the output reaches the rail); with a lead
// interrupted the overload detector drives the output to the positive rail
// (the alarm). Marlin's TEMP_SENSOR -1 reads it as raw × 500 / 1024 degC.
// The ±1/±3 °C calibration error and the type K non-linearity the AD595 does
// not correct are not modelled.
//
// Fault: "open" (a thermocouple lead broken: the output at the supply).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/TraceThrottle.hpp"

namespace avrbench {

class ThermalBody;

class ThermocoupleAmplifier final : public Part {
public:
    static std::vector<ParamSpec> param_specs();
    static const std::map<std::string, std::map<std::string, std::string>>& presets();

    // Port `body` requires the thermal_plant whose sensor node the junction
    // sits on; port `out` provides the amplifier's output for an ADC pin of
    // `clock`.
    ThermocoupleAmplifier(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "thermocouple_amplifier"; }

    // The output for a junction temperature, clamped to 0 .. supply.
    double output_volts(double degC) const;
    std::uint64_t samples() const { return samples_; }
    std::vector<std::string> fault_names() const override { return {"open"}; }

private:
    void connect_body(ThermalBody& body);
    double sample(Cycle cycle);
    void apply_fault(const std::string& fault) override;

    ThermalBody* plant_ = nullptr;
    double volts_per_degC_, supply_v_;
    bool open_ = false;
    std::uint64_t samples_ = 0;
    TraceThrottle trace_;
    std::size_t sig_temperature_ = 0, sig_volts_ = 0;
};

}  // namespace avrbench
