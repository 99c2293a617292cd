#include "parts/Heater.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>

#include "core/Errors.hpp"
#include "parts/ThermalBody.hpp"

namespace avrbench {

REGISTER_PART(Heater, "heater");

std::vector<ParamSpec> Heater::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "preset", .type = PT::Choice, .default_value = "cartridge_40w_12v",
         .choices = {"cartridge_40w_12v", "cartridge_40w_24v", "bed_12v", "custom"}, .help = "heater element"},
        {.name = "node", .type = PT::Choice, .default_value = "block", .choices = {"block", "surface"},
         .help = "the plant node it heats"},
        {.name = "supply", .type = PT::Quantity, .dimension = D::Voltage, .source = "preset",
         .help = "heater supply voltage"},
        {.name = "resistance", .type = PT::Quantity, .dimension = D::Resistance, .source = "preset",
         .help = "heater element resistance", .min = 1e-3},  // no heater element is below a milliohm
        {.name = "series_resistance", .type = PT::Quantity, .dimension = D::Resistance, .default_value = "0ohm",
         .source = "assumed: negligible", .help = "MOSFET on-resistance plus wiring"},
        {.name = "gate_active", .type = PT::Choice, .default_value = "high", .choices = {"high", "low"},
         .source = "RAMPS 1.4 schematic: the MCU pin drives the N-MOSFET gate directly, high = on",
         .help = "gate level that turns the heater on"},
        {.name = "sample_interval", .type = PT::Quantity, .dimension = D::Time, .default_value = "100ms",
         .source = "assumed", .help = "period of the duty trace"},
    };
}

const std::map<std::string, std::map<std::string, std::string>>& Heater::presets() {
    static const std::map<std::string, std::map<std::string, std::string>> table = {
        // A 40 W cartridge at its rated voltage: R = V^2 / P = 144 / 40 = 3.6 ohm
        // (12 V) and 576 / 40 = 14.4 ohm (24 V). (Marlin's Anycubic i3 Mega
        // configuration notes "40W heater cartridge (3.6 ohm @ 22 degC)".)
        {"cartridge_40w_12v", {{"supply", "12V"}, {"resistance", "3.6ohm"}}},
        {"cartridge_40w_24v", {{"supply", "24V"}, {"resistance", "14.4ohm"}}},
        // RepRap wiki "Heatbeds - A beginner's guide": a PCB heatbed makes about
        // 120 W at 12 V, so its tracks measure about 1.2 ohm.
        {"bed_12v", {{"supply", "12V"}, {"resistance", "1.2ohm"}}},
        {"custom", {}},
    };
    return table;
}

Heater::Heater(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock), node_(params.text("node")) {
    if (!params.has("supply") || !params.has("resistance")) {
        throw part_error(this->name(), "a custom heater needs supply and resistance");
    }
    const double v = params.quantity("supply");
    const double r = params.quantity("resistance");
    const double rs = params.quantity("series_resistance");
    if (!(r > 0)) throw part_error(this->name(), "resistance must be positive");
    if (!(rs >= 0)) throw part_error(this->name(), "the switch resistance must not be negative");
    if (!(v >= 0)) throw part_error(this->name(), "the supply voltage must not be negative");
    // P = I^2 R with I = V / (R + R_series).
    power_on_W_ = v * v * r / ((r + rs) * (r + rs));
    gate_active_level_ = params.text("gate_active") == "high";
    gate_pin_ = add_pin("gate", TerminalRole::Input);
    const double interval = params.quantity("sample_interval");
    if (!(interval > 0)) throw part_error(this->name(), "sample_interval must be positive");
    sample_cycles_ = std::max<Cycle>(1, clock.cycles_from_seconds(interval));
    require_port<ThermalBody>("body", true, "the thermal_plant it heats",
                              [this](ThermalBody& body, Part& plant) { connect_body(body, plant); });
}

void Heater::connect_body(ThermalBody& body, Part& plant) {
    plant_ = &body;
    try {
        source_ = plant_->add_heat_source(node_, power_on_W_);
    } catch (const BadInput& e) {
        throw part_error(name(), e.what());
    }
    sig_on_ = add_signal({"on", false, "", "heater-on", plant.name()}, 0);
    sig_duty_ = add_signal({"duty", true, "", "heater-duty", plant.name()}, 0);
    sig_power_ = add_signal({"power_W", true, "W", "heater-power", plant.name()}, 0);
}

void Heater::start() {
    last_sample_ = clock().cycle();
    update();
    clock().scheduler().at(last_sample_ + sample_cycles_, [this](Cycle c) { on_sample(c); });
}

namespace {
constexpr double kMaxAveragedPeriod_s = 2.5e-3;  // see Heater.hpp
}

Cycle Heater::on_cycles() const {
    const Cycle now = clock().cycle();
    if (waving_) return on_total_ + wave_on_cycles(wave_from_, now);
    return on_total_ + (on_ ? now - on_since_ : 0);
}

Cycle Heater::wave_on_cycles(Cycle a, Cycle b) const {
    if (b <= a) return 0;
    const Cycle high = wave_.high_cycles_until(b) - wave_.high_cycles_until(a);
    return gate_active_level_ ? high : (b - a) - high;
}

bool Heater::gate_on_now() const {
    const bool level = waving_ ? wave_.level_at(clock().cycle()) : input_level(gate_pin_);
    return level == gate_active_level_;
}

bool Heater::begin_input_wave(std::size_t pin, const PeriodicWave& wave) {
    if (pin != gate_pin_ || signals_watched() || fault_state_ != Fault::None) return false;
    if (static_cast<double>(wave.period) > kMaxAveragedPeriod_s * clock().frequency_hz()) return false;
    const Cycle now = clock().cycle();
    if (on_) on_total_ += now - on_since_;
    waving_ = true;
    wave_ = wave;
    wave_from_ = now;
    const double duty = static_cast<double>(wave_on_cycles(wave.start, wave.start + wave.period)) /
                        static_cast<double>(wave.period);
    plant_->set_heat_source_power(source_, power_on_W_ * duty);
    return true;
}

void Heater::end_input_wave(std::size_t pin, Cycle) {
    if (pin != gate_pin_ || !waving_) return;
    const Cycle now = clock().cycle();
    on_total_ += wave_on_cycles(wave_from_, now);
    waving_ = false;
    // The gate's level at the period boundary, from the net again.
    on_ = gate_on_now();
    on_since_ = now;
    plant_->set_heat_source_power(source_, on_ ? power_on_W_ : 0.0);
    publish(sig_on_, on_ ? 1 : 0);
}

double Heater::energy_J() const {
    return static_cast<double>(on_cycles()) / clock().frequency_hz() * power_on_W_;
}

void Heater::inject(Fault fault, Cycle at_cycle) {
    static const char* const kNames[] = {"none", "disconnected", "stuck_on"};
    inject_fault(kNames[static_cast<int>(fault)], at_cycle);
}

void Heater::apply_fault(const std::string& fault) {
    // Back to the gate's edges first (the wave ends at its last period
    // boundary; the edges since then arrive): a fault is not followed in a wave.
    if (waving_) clock().settle_periodic_outputs();
    fault_state_ = fault == "disconnected" ? Fault::Disconnected : fault == "stuck_on" ? Fault::StuckOn : Fault::None;
    update();
}

void Heater::on_input(std::size_t pin, bool) {
    if (pin == gate_pin_) update();
}

void Heater::update() {
    if (waving_) return;  // no edges arrive meanwhile, and a fault ends the wave first
    const Cycle now = clock().cycle();
    const bool on = fault_state_ == Fault::StuckOn || (fault_state_ == Fault::None && gate_on_now());
    if (on == on_) return;
    if (on_) on_total_ += now - on_since_;
    on_ = on;
    on_since_ = now;
    plant_->set_heat_source_power(source_, on ? power_on_W_ : 0.0);
    publish(sig_on_, on ? 1 : 0);
}

void Heater::on_sample(Cycle scheduled) {
    const Cycle now = clock().cycle();
    const Cycle on_now = on_cycles();
    const Cycle span = now - last_sample_;
    const double duty = span > 0 ? static_cast<double>(on_now - on_at_last_sample_) / static_cast<double>(span) : 0.0;
    last_sample_ = now;
    on_at_last_sample_ = on_now;
    publish(sig_duty_, duty);
    publish(sig_power_, duty * power_on_W_);
    clock().scheduler().at(scheduled + sample_cycles_, [this](Cycle c) { on_sample(c); });
}

}  // namespace avrbench
