#include "parts/Thermistor.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "periph/adc/Adc.hpp"
#include "core/Errors.hpp"
#include "parts/ThermalBody.hpp"

namespace avrbench {

REGISTER_PART(Thermistor, "thermistor");
namespace {

constexpr double kKelvin = 273.15;

}  // namespace

NtcCurve NtcCurve::fit(const std::array<std::pair<double, double>, 3>& points) {
    // The standard closed form of the 3x3 system 1/T_i = A + B L_i + C L_i^3.
    const double l1 = std::log(points[0].second), l2 = std::log(points[1].second), l3 = std::log(points[2].second);
    const double y1 = 1.0 / (points[0].first + kKelvin), y2 = 1.0 / (points[1].first + kKelvin),
                 y3 = 1.0 / (points[2].first + kKelvin);
    const double g2 = (y2 - y1) / (l2 - l1), g3 = (y3 - y1) / (l3 - l1);
    NtcCurve c;
    c.c = (g3 - g2) / (l3 - l2) / (l1 + l2 + l3);
    c.b = g2 - c.c * (l1 * l1 + l1 * l2 + l2 * l2);
    c.a = y1 - (c.b + l1 * l1 * c.c) * l1;
    return c;
}

NtcCurve NtcCurve::from_beta(double r25_ohm, double t25_degC, double beta_K) {
    auto r = [&](double t) { return r25_ohm * std::exp(beta_K * (1.0 / (t + kKelvin) - 1.0 / (t25_degC + kKelvin))); };
    return fit({{{25.0, r(25.0)}, {150.0, r(150.0)}, {250.0, r(250.0)}}});
}

double NtcCurve::resistance_ohm(double degC) const {
    const double inv_t = 1.0 / (degC + kKelvin);
    // Solve C x^3 + B x + (A - 1/T) = 0 for x = ln R (Cardano; one real root
    // since B, C > 0), or the linear case when C vanishes (beta curves).
    if (std::abs(c) < 1e-15) return std::exp((inv_t - a) / b);
    const double y = (a - inv_t) / c;
    const double x = std::sqrt(std::pow(b / (3.0 * c), 3) + y * y / 4.0);
    return std::exp(std::cbrt(x - y / 2.0) - std::cbrt(x + y / 2.0));
}

double NtcCurve::temperature_degC(double ohm) const {
    const double l = std::log(ohm);
    return 1.0 / (a + b * l + c * l * l * l) - kKelvin;
}

std::vector<ParamSpec> Thermistor::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "preset", .type = PT::Choice, .default_value = "epcos_b57560g104f",
         .choices = {"epcos_b57560g104f", "ntc_100k_3950", "custom"},
         .help = "epcos_b57560g104f (Marlin thermistor 1, its default), ntc_100k_3950, or custom points / beta"},
        {.name = "t1", .type = PT::Quantity, .dimension = D::Temperature, .source = "preset",
         .help = "first datasheet point"},
        {.name = "r1", .type = PT::Quantity, .dimension = D::Resistance, .source = "preset"},
        {.name = "t2", .type = PT::Quantity, .dimension = D::Temperature, .source = "preset",
         .help = "second datasheet point"},
        {.name = "r2", .type = PT::Quantity, .dimension = D::Resistance, .source = "preset"},
        {.name = "t3", .type = PT::Quantity, .dimension = D::Temperature, .source = "preset",
         .help = "third datasheet point"},
        {.name = "r3", .type = PT::Quantity, .dimension = D::Resistance, .source = "preset"},
        {.name = "beta", .type = PT::Quantity, .source = "preset",
         .help = "beta in K, with t1/r1 as the reference point (instead of t2..r3)", .min = 100, .max = 1e5},
        {.name = "leg", .type = PT::Choice, .default_value = "lower", .choices = {"lower", "upper"},
         .source = "RAMPS 1.4 schematic and seed 001: NTC from the pin to GND",
         .help = "where the NTC sits in the divider"},
        {.name = "pullup", .type = PT::Quantity, .dimension = D::Resistance, .default_value = "4.7kohm",
         .source = "RAMPS 1.4 schematic: 4.7 kohm pull-ups R25/R26/R27", .help = "the divider's fixed resistor"},
        {.name = "reference", .type = PT::Quantity, .dimension = D::Voltage, .default_value = "5V",
         .source = "Arduino Mega / UNO: the divider hangs from the 5 V rail = AVCC",
         .help = "voltage at the top of the divider"},
        {.name = "noise", .type = PT::Quantity, .dimension = D::Voltage, .default_value = "0V",
         .source = "assumed: none unless asked", .help = "RMS Gaussian noise added to each sample"},
        {.name = "seed", .type = PT::Integer, .default_value = "1", .help = "seed of the noise generator", .min = 0,
         .max = 9007199254740992.0},
        {.name = "sample_interval", .type = PT::Quantity, .dimension = D::Time, .default_value = "100ms",
         .source = "assumed", .help = "at most one trace value per interval"},
    };
}

const std::map<std::string, std::map<std::string, std::string>>& Thermistor::presets() {
    static const std::map<std::string, std::map<std::string, std::string>> table = {
        // EPCOS (TDK) B57560G104F: three points of its datasheet R/T table, as
        // Klipper tabulates them (klippy/extras/thermistor.py):
        // 100 kohm at 25 degC, 1641.9 ohm at 150 degC, 226.15 ohm at 250 degC.
        {"epcos_b57560g104f", {{"t1", "25degC"}, {"r1", "100kohm"}, {"t2", "150degC"}, {"r2", "1641.9ohm"},
                               {"t3", "250degC"}, {"r3", "226.15ohm"}}},
        // The generic "100k 3950" NTC: R25 = 100 kohm, beta(25/50) = 3950 K.
        {"ntc_100k_3950", {{"t1", "25degC"}, {"r1", "100kohm"}, {"beta", "3950"}}},
        {"custom", {}},
    };
    return table;
}

Thermistor::Thermistor(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      rng_(static_cast<std::uint64_t>(params.integer("seed"))),
      trace_(clock, params.quantity("sample_interval"), "part '" + this->name() + "': ") {
    const std::string where = "part '" + this->name() + "': ";
    if (!params.has("t1") || !params.has("r1")) throw BadInput(where + "a custom thermistor needs t1 and r1");
    if (params.has("beta")) {
        curve_ = NtcCurve::from_beta(params.quantity("r1"), params.quantity("t1"), params.quantity("beta"));
    } else {
        for (const char* p : {"t2", "r2", "t3", "r3"}) {
            if (!params.has(p)) throw BadInput(where + "give beta, or three points t1/r1, t2/r2, t3/r3");
        }
        curve_ = NtcCurve::fit({{{params.quantity("t1"), params.quantity("r1")},
                                 {params.quantity("t2"), params.quantity("r2")},
                                 {params.quantity("t3"), params.quantity("r3")}}});
    }
    if (!(curve_.b > 0) || !std::isfinite(curve_.a) || !std::isfinite(curve_.c)) {
        throw BadInput(where + "the points do not describe an NTC (resistance must fall as temperature rises)");
    }
    lower_leg_ = params.text("leg") == "lower";
    fixed_ohm_ = params.quantity("pullup");
    reference_v_ = params.quantity("reference");
    noise_v_ = params.quantity("noise");
    if (!(fixed_ohm_ > 0) || !(reference_v_ > 0) || noise_v_ < 0) {
        throw BadInput(where + "pullup and reference must be positive, noise not negative");
    }

    require_port<ThermalBody>("body", true, "the thermal_plant whose sensor node it is",
                              [this](ThermalBody& body) { connect_body(body); });
    provide_analog("out", [this](Cycle c) { return sample(c); }, "the divider's output, for an ADC pin");
}

void Thermistor::connect_body(ThermalBody& body) {
    plant_ = &body;
    plant_->attach_sensor();
    sig_temperature_ = add_signal("bead_degC", true, plant_->sensor_degC());
    sig_volts_ = add_signal("volts", true, divider_volts(plant_->sensor_degC()));
}

double Thermistor::divider_volts_for_resistance(double ohm) const {
    if (std::isinf(ohm)) return lower_leg_ ? reference_v_ : 0.0;
    return lower_leg_ ? reference_v_ * ohm / (ohm + fixed_ohm_) : reference_v_ * fixed_ohm_ / (fixed_ohm_ + ohm);
}

double Thermistor::divider_volts(double degC) const { return divider_volts_for_resistance(curve_.resistance_ohm(degC)); }

double Thermistor::volts_now() {
    const double t = plant_->sensor_degC();
    switch (fault_state_) {
        case Fault::Open: return divider_volts_for_resistance(std::numeric_limits<double>::infinity());
        case Fault::Shorted: return divider_volts_for_resistance(0.0);
        default: return divider_volts(t);
    }
}

// Box–Muller on the raw 64-bit engine output, so the sequence is the same on
// every platform (std::normal_distribution is implementation-defined).
double Thermistor::gaussian() {
    const double u1 = (static_cast<double>(rng_() >> 11) + 1.0) * 0x1.0p-53;  // (0, 1]
    const double u2 = static_cast<double>(rng_() >> 11) * 0x1.0p-53;          // [0, 1)
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
}

double Thermistor::sample(Cycle cycle) {
    ++samples_;
    plant_->sensor_read(cycle);
    double v = volts_now();
    if (noise_v_ > 0) v = std::clamp(v + noise_v_ * gaussian(), 0.0, reference_v_);
    if (trace_.due(cycle)) {
        publish(sig_temperature_, plant_->sensor_degC());
        publish(sig_volts_, v);
    }
    return v;
}

void Thermistor::inject(Fault fault, Cycle at_cycle) {
    static const char* const kNames[] = {"none", "open", "shorted", "detached"};
    inject_fault(kNames[static_cast<int>(fault)], at_cycle);
}

void Thermistor::apply_fault(const std::string& fault) {
    fault_state_ = fault == "open"       ? Fault::Open
                   : fault == "shorted"  ? Fault::Shorted
                   : fault == "detached" ? Fault::Detached
                                         : Fault::None;
    plant_->set_sensor_detached(fault_state_ == Fault::Detached);
}

}  // namespace avrbench
