#include "parts/HallEndstop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/Errors.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(HallEndstop, "hall_endstop");

std::vector<ParamSpec> HallEndstop::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "position", .type = PT::Quantity, .dimension = D::Length, .default_value = "0mm",
         .source = "board layout", .help = "where the sensor sits along the axis (the carriage position facing it)"},
        {.name = "field_at_magnet_G", .type = PT::Quantity, .default_value = "1000",
         .source = "assumed: a 5 x 2 mm N35 disc magnet, about 1000 G at 1 mm from its face",
         .help = "B0: the field with the magnet facing the sensor (gauss)", .min = 1, .max = 20000},
        {.name = "falloff", .type = PT::Quantity, .dimension = D::Length, .default_value = "3mm",
         .source = "assumed: of the order of the magnet's size (a dipole's far field falls as 1/d^3 beyond it)",
         .help = "d0 in B(d) = B0 / (1 + (d/d0)^2)^1.5", .min = 1e-4, .max = 1},
        {.name = "operate_G", .type = PT::Quantity, .default_value = "250",
         .source = "Allegro A3144 datasheet: operate point 70..350 G; assumed mid-range",
         .help = "open drain: on (low) from this field up (gauss)", .min = 1, .max = 20000},
        {.name = "release_G", .type = PT::Quantity, .default_value = "200",
         .source = "Allegro A3144 datasheet: release point 50..330 G, hysteresis at least 20 G",
         .help = "open drain: off (released) from this field down (gauss)", .min = 0, .max = 20000},
        {.name = "supply", .type = PT::Quantity, .dimension = D::Voltage, .default_value = "5V",
         .source = "the board's logic supply", .help = "the linear output's supply (ratiometric)"},
        {.name = "sensitivity_mV_per_G", .type = PT::Quantity, .default_value = "5",
         .source = "Allegro A1324 datasheet: 5.0 mV/G typical at 5 V", .help = "the linear output's slope",
         .min = 0.01, .max = 100},
    };
}

HallEndstop::HallEndstop(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      sensor_mm_(params.quantity("position") * 1e3),
      b0_G_(params.quantity("field_at_magnet_G")),
      d0_mm_(params.quantity("falloff") * 1e3),
      operate_G_(params.quantity("operate_G")),
      release_G_(params.quantity("release_G")),
      supply_v_(params.quantity("supply")),
      sensitivity_v_per_G_(params.quantity("sensitivity_mV_per_G") * 1e-3) {
    if (!(release_G_ < operate_G_)) throw part_error(this->name(), "release_G must be below operate_G");
    out_pin_ = add_pin("out", TerminalRole::Output);
    provide_analog("analog", [this](Cycle) { return analog_volts_now(); }, "the linear output, for an ADC pin");
    sig_field_ = add_signal({"field_G", true, "G", "", ""}, 0);
    sig_on_ = add_signal("on", false);
    require_port<Carriage>("axis", true, "a linear axis' carriage", [this](Carriage& axis) { connect_axis(axis); });
}

void HallEndstop::connect_axis(Carriage& axis) {
    axis_ = &axis;
    if (sensor_mm_ < 0 || sensor_mm_ > axis.travel_mm()) {
        throw part_error(name(), "position must lie within the axis' travel (0.." +
                       std::to_string(axis.travel_mm()) + " mm)");
    }
    axis.on_move([this](double) { update(); });
}

double HallEndstop::field_G() const {
    const double u = (axis_->position_mm() - sensor_mm_) / d0_mm_;
    return b0_G_ / std::pow(1.0 + u * u, 1.5);
}

double HallEndstop::analog_volts_now() const {
    // A1324: the output swings between about 0.2 V and supply - 0.2 V (assumed rails).
    return std::clamp(supply_v_ / 2 + sensitivity_v_per_G_ * field_G(), 0.2, supply_v_ - 0.2);
}

void HallEndstop::start() {
    release_output(out_pin_);
    update();
}

void HallEndstop::update() {
    const double b = field_G();
    publish(sig_field_, b);
    const bool on = on_ ? b > release_G_ : b >= operate_G_;
    if (on == on_) return;
    on_ = on;
    if (on) {
        ++trips_;
        drive_output(out_pin_, false);
    } else {
        release_output(out_pin_);
    }
    publish(sig_on_, on ? 1 : 0);
}

std::string HallEndstop::summary() {
    char line[160];
    std::snprintf(line, sizeof line, "%s: %s, %.1f G at the sensor, tripped %u time%s", name().c_str(),
                  on_ ? "on" : "off", field_G(), trips_, trips_ == 1 ? "" : "s");
    return line;
}

}  // namespace avrbench
