#include "parts/ThermocoupleAmplifier.hpp"

#include <algorithm>

#include "core/Errors.hpp"
#include "parts/PartRegistry.hpp"
#include "parts/ThermalBody.hpp"

namespace avrbench {

REGISTER_PART(ThermocoupleAmplifier, "thermocouple_amplifier");

std::vector<ParamSpec> ThermocoupleAmplifier::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "preset", .type = PT::Choice, .default_value = "ad595", .choices = {"ad595", "custom"},
         .help = "ad595 (type K, 10 mV/degC: Marlin's TEMP_SENSOR -1), or custom with gain_mV_per_degC"},
        {.name = "gain_mV_per_degC", .source = "preset", .help = "output per degree",
         .min = 0.01, .max = 1000},
        {.name = "supply", .type = PT::Quantity, .dimension = D::Voltage, .default_value = "5V",
         .source = "RAMPS/Ultimaker thermocouple boards: the AD595 on the 5 V rail (AD595 datasheet: single +5 V supply)",
         .help = "the positive rail: the output's ceiling and where an open thermocouple drives it"},
        {.name = "sample_interval", .type = PT::Quantity, .dimension = D::Time, .default_value = "100ms",
         .source = "assumed", .help = "at most one trace value per interval"},
    };
}

const std::map<std::string, std::map<std::string, std::string>>& ThermocoupleAmplifier::presets() {
    static const std::map<std::string, std::map<std::string, std::string>> table = {
        // AD594/AD595 datasheet, features: "Low Impedance Voltage Output: 10 mV/°C".
        {"ad595", {{"gain_mV_per_degC", "10"}}},
        {"custom", {}},
    };
    return table;
}

ThermocoupleAmplifier::ThermocoupleAmplifier(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock), trace_(clock, params.quantity("sample_interval"), "part '" + this->name() + "': ") {
    const std::string where = "part '" + this->name() + "': ";
    if (!params.has("gain_mV_per_degC")) throw BadInput(where + "a custom thermocouple_amplifier needs gain_mV_per_degC");
    volts_per_degC_ = params.quantity("gain_mV_per_degC") / 1000.0;
    supply_v_ = params.quantity("supply");
    if (!(supply_v_ > 0)) throw BadInput(where + "supply must be positive");
    require_port<ThermalBody>("body", true, "the thermal_plant whose sensor node the junction is on",
                              [this](ThermalBody& body) { connect_body(body); });
    provide_analog("out", [this](Cycle c) { return sample(c); }, "the amplifier's output, for an ADC pin");
}

void ThermocoupleAmplifier::connect_body(ThermalBody& body) {
    plant_ = &body;
    plant_->attach_sensor();
    sig_temperature_ = add_signal("junction_degC", true, plant_->sensor_degC());
    sig_volts_ = add_signal("volts", true, output_volts(plant_->sensor_degC()));
}

double ThermocoupleAmplifier::output_volts(double degC) const {
    return std::clamp(volts_per_degC_ * degC, 0.0, supply_v_);
}

double ThermocoupleAmplifier::sample(Cycle cycle) {
    ++samples_;
    plant_->sensor_read(cycle);
    const double v = open_ ? supply_v_ : output_volts(plant_->sensor_degC());
    if (trace_.due(cycle)) {
        publish(sig_temperature_, plant_->sensor_degC());
        publish(sig_volts_, v);
    }
    return v;
}

void ThermocoupleAmplifier::apply_fault(const std::string& fault) { open_ = fault == "open"; }

}  // namespace avrbench
