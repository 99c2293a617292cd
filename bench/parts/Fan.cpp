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
        {.name = "full_speed_rpm", .type = PT::Integer, .default_value = "5000",
         .source = "assumed: a 40 mm fan at full speed (Noctua NF-A4x10 5V: 5000 rpm)",
         .help = "revolutions per minute at full drive (the tachometer's rate)", .min = 1, .max = 100000},
        {.name = "tach_pullup", .type = PT::Quantity, .dimension = D::Resistance, .default_value = "0ohm",
         .source = "the board's pull-up on the tachometer line (0: none, the MCU's own if the firmware enables it)",
         .help = "pull-up resistor on the open-collector tachometer output", .min = 0, .max = 1e7},
        {.name = "pulses_per_rev", .type = PT::Integer, .default_value = "2",
         .source = "Intel 4-Wire PWM Fan Specification rev. 1.3: two tachometer pulses per revolution",
         .help = "tachometer periods per revolution", .min = 1, .max = 16},
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
    tach_pin_ = add_pin("tach", TerminalRole::Output);
    full_speed_rpm_ = static_cast<double>(params.integer("full_speed_rpm"));
    pulses_per_rev_ = static_cast<unsigned>(params.integer("pulses_per_rev"));
    tach_pullup_ohm_ = params.quantity("tach_pullup");
    add_readout("rpm", [this] { return rpm(); });
    sig_speed_ = add_signal("speed", true, 0);
    require_port<ThermalBody>("body", false, "the thermal_plant it cools (none: a fan that cools nothing modelled, a heat sink's)",
                              [this](ThermalBody& body) { connect_body(body); });
}

void Fan::connect_body(ThermalBody& body) {
    plant_ = &body; }

void Fan::start() {
    last_cycle_ = clock().cycle();
    update();
    clock().scheduler().at(last_cycle_ + sample_cycles_, [this](Cycle c) { on_sample(c); });
    if (connected(tach_pin_)) release_tach();
}

// The open collector off: the line is what its pull-up (or nothing) makes it.
void Fan::release_tach() {
    if (tach_pullup_ohm_ > 0) {
        pull_output(tach_pin_, true, tach_pullup_ohm_);
    } else {
        release_output(tach_pin_);
    }
}

// Below this fraction of full speed the tachometer gives no edges (a fan
// that is not turning; its next check is the next sample).
constexpr double kSlowestTachSpeed = 0.01;

// The next tachometer edge: half a period at the present speed, the speed
// taken as constant for that half period (it changes over the spin time
// constant, hundreds of half periods).
void Fan::schedule_tach(Cycle from) {
    const double revs_per_s = speed() * full_speed_rpm_ / 60.0;
    if (speed() < kSlowestTachSpeed || revs_per_s <= 0) {
        tach_running_ = false;
        return;
    }
    const double half_period_s = 1.0 / (2.0 * revs_per_s * pulses_per_rev_);
    tach_running_ = true;
    clock().scheduler().at(from + std::max<Cycle>(1, clock().cycles_from_seconds(half_period_s)), [this](Cycle c) { on_tach(c); });
}

void Fan::on_tach(Cycle scheduled) {
    tach_low_ = !tach_low_;
    ++tach_edges_;
    if (tach_low_) {
        drive_output(tach_pin_, false);
    } else {
        release_tach();
    }
    schedule_tach(scheduled);
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
    if (plant_ != nullptr && (std::abs(s - plant_->fan_speed()) >= 1e-4 || (s == target && plant_->fan_speed() != target))) {
        plant_->set_fan_speed(s);
    }
    publish(sig_speed_, speed_);
    if (!tach_running_ && connected(tach_pin_)) schedule_tach(scheduled);
    clock().scheduler().at(scheduled + sample_cycles_, [this](Cycle c) { on_sample(c); });
}

}  // namespace avrbench
