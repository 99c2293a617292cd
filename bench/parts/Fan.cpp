#include "parts/Fan.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
#include <cmath>

#include "core/Errors.hpp"
#include "parts/ThermalBody.hpp"

namespace avrbench {

REGISTER_PART(Fan, "fan");

std::vector<ParamSpec> Fan::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "active", .type = PT::Choice, .default_value = "high", .choices = {"high", "low"},
         .source = "RAMPS 1.4 schematic: D9 drives the fan MOSFET gate, high = on",
         .help = "drive level that runs the fan"},
        {.name = "spin_time_constant", .type = PT::Quantity, .dimension = D::Time, .default_value = "0.5s",
         .source = "assumed: a 40 mm / 50 mm blower reaches 63 % of full speed in about half a second",
         .help = "first-order lag of the speed behind the drive"},
        {.name = "sample_interval", .type = PT::Quantity, .dimension = D::Time, .default_value = "50ms",
         .source = "assumed", .help = "how often the plant gets the current speed"},
    };
}

Fan::Fan(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    active_level_ = params.text("active") == "high";
    tau_s_ = params.quantity("spin_time_constant");
    const double interval = params.quantity("sample_interval");
    if (tau_s_ < 0 || !(interval > 0)) {
        throw part_error(this->name(), "spin_time_constant and sample_interval must be positive");
    }
    sample_cycles_ = std::max<Cycle>(1, clock.cycles_from_seconds(interval));
    pwm_pin_ = add_pin("pwm", TerminalRole::Input);
    sig_speed_ = add_signal("speed", true, 0);
    require_port<ThermalBody>("body", true, "the thermal_plant it cools",
                              [this](ThermalBody& body) { connect_body(body); });
}

void Fan::connect_body(ThermalBody& body) {
    plant_ = &body; }

void Fan::start() {
    last_cycle_ = clock().cycle();
    update();
    clock().scheduler().at(last_cycle_ + sample_cycles_, [this](Cycle c) { on_sample(c); });
}

// Exact solution of tau ds/dt = drive - s over the time since the last event.
void Fan::settle_speed() {
    const Cycle now = clock().cycle();
    if (now <= last_cycle_) return;
    const double target = driven_ ? 1.0 : 0.0;
    const double dt = static_cast<double>(now - last_cycle_) / clock().frequency_hz();
    speed_ = tau_s_ > 0 ? target + (speed_ - target) * std::exp(-dt / tau_s_) : target;
    last_cycle_ = now;
}

double Fan::speed() const {
    const double target = driven_ ? 1.0 : 0.0;
    const double dt = static_cast<double>(clock().cycle() - last_cycle_) / clock().frequency_hz();
    return tau_s_ > 0 ? target + (speed_ - target) * std::exp(-dt / tau_s_) : target;
}

void Fan::inject(Fault fault, Cycle at_cycle) { inject_fault(fault == Fault::Stopped ? "stopped" : "none", at_cycle); }

void Fan::apply_fault(const std::string& fault) {
    stopped_ = fault == "stopped";
    update();
}

void Fan::on_input(std::size_t pin, bool) {
    if (pin == pwm_pin_) update();
}

void Fan::update() {
    const bool driven = !stopped_ && input_level(pwm_pin_) == active_level_;
    if (driven == driven_) return;
    settle_speed();
    driven_ = driven;
}

void Fan::on_sample(Cycle scheduled) {
    settle_speed();
    // Changes below 1e-4 of full speed (3 uW/K on the e3d_v6 preset) are not
    // worth a new decomposition of the plant's model.
    // Within 1e-4 of its target the speed counts as there.
    const double target = driven_ ? 1.0 : 0.0;
    const double s = std::abs(speed_ - target) < 1e-4 ? target : speed_;
    if (std::abs(s - plant_->fan_speed()) >= 1e-4 || (s == target && plant_->fan_speed() != target)) {
        plant_->set_fan_speed(s);
    }
    publish(sig_speed_, speed_);
    clock().scheduler().at(scheduled + sample_cycles_, [this](Cycle c) { on_sample(c); });
}

}  // namespace avrbench
