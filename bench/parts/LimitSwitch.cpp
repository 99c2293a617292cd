#include "parts/LimitSwitch.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/Errors.hpp"
#include "core/Units.hpp"

namespace avrbench {

REGISTER_PART(LimitSwitch, "limit_switch");

std::vector<ParamSpec> LimitSwitch::param_specs() {
    using PT = ParamType;
    return {
        {.name = "side", .type = PT::Choice, .default_value = "min", .choices = {"min", "max"},
         .help = "min: trips at or below position; max: at or above"},
        {.name = "position", .type = PT::Quantity, .dimension = Dimension::Length,
         .help = "trip position (default: 0 for min, the travel for max)"},
        {.name = "hysteresis", .type = PT::Quantity, .dimension = Dimension::Length, .default_value = "0.05mm",
         .source = "assumed: a typical microswitch's differential travel",
         .help = "travel past the trip point before it releases"},
        {.name = "contact", .type = PT::Choice, .default_value = "NO", .choices = {"NO", "NC"},
         .help = "normally open or closed"},
        {.name = "switched_to", .type = PT::Choice, .default_value = "gnd", .choices = {"gnd", "vcc"},
         .help = "what the closed contact connects the signal to"},
        {.name = "pull", .type = PT::Choice, .default_value = "internal_up",
         .choices = {"internal_up", "external_up", "external_down", "none", "push_pull"},
         .help = "what sets the level while the contact is open (push_pull: a sensor whose output stage drives both "
         "levels, e.g. an optical endstop)"},
        {.name = "pull_resistance", .type = PT::Quantity, .dimension = Dimension::Resistance,
         .default_value = "10kohm",
         .source = "assumed: the 10 kohm pull-up of common endstop boards (RepRap mechanical endstop v1.2)",
         .help = "the external pull resistor (external_up / external_down)"},
        {.name = "bounce", .type = PT::Quantity, .dimension = Dimension::Time, .default_value = "0s",
         .source = "assumed: no bounce unless asked", .help = "duration of contact bounce after each transition"},
        {.name = "bounce_edges", .type = PT::Integer, .default_value = "4", .source = "assumed",
         .help = "extra make/break pairs during a bounce, at most", .min = 0, .max = 1000},
        {.name = "seed", .type = PT::Integer, .default_value = "1", .help = "seed for the bounce timing", .min = 0,
         .max = 9007199254740992.0},
    };
}

LimitSwitch::LimitSwitch(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      position_given_(params.has("position")),
      position_m_(position_given_ ? params.quantity("position") : 0.0),
      min_side_(params.text("side") == "min"),
      hysteresis_m_(params.quantity("hysteresis")),
      normally_open_(params.text("contact") == "NO"),
      closed_level_(params.text("switched_to") == "vcc"),
      pull_(params.text("pull")),
      pull_ohm_(params.quantity("pull_resistance")),
      bounce_s_(params.quantity("bounce") >= 0 && params.quantity("bounce") <= 1.0
                    ? params.quantity("bounce")
                    : throw BadInput("parameter 'bounce' must be from 0 to 1 s (contacts settle in milliseconds)")),
      bounce_edges_(static_cast<unsigned>(checked_integer(static_cast<double>(params.integer("bounce_edges")),
                                                          "parameter 'bounce_edges'", 0, 1000))),
      rng_(static_cast<std::uint64_t>(checked_integer(static_cast<double>(params.integer("seed")), "parameter 'seed'", 0,
                                                      std::int64_t{1} << 53))) {
    out_pin_ = add_pin("out", TerminalRole::Output);
    sig_closed_ = add_signal("closed", false);
    require_port<Carriage>("axis", true, "a linear axis' carriage", [this](Carriage& axis) { connect_axis(axis); });
}

void LimitSwitch::connect_axis(Carriage& axis) {
    axis_ = &axis;
    const double travel_m = axis_->travel_mm() * 1e-3;
    trip_m_ = position_given_ ? position_m_ : (min_side_ ? 0.0 : travel_m);
    if (trip_m_ < 0 || trip_m_ > travel_m) {
        throw part_error(name(), "position must lie within the axis' travel (0.." +
                       std::to_string(axis_->travel_mm()) + " mm)");
    }
    axis_->on_move([this](double position_m) { on_axis_move(position_m); });
}

bool LimitSwitch::contact_closed() const {
    if (fault() == "stuck_closed") return true;
    if (fault() == "stuck_open") return false;
    return normally_open_ ? triggered_ : !triggered_;
}

void LimitSwitch::apply_fault(const std::string&) { set_contact(contact_closed()); }

void LimitSwitch::start() {
    on_axis_move(axis_->position_mm() * 1e-3);
    apply_contact(contact_closed());
}

void LimitSwitch::on_axis_move(double position_m) {
    // Half a micrometre of slack so a carriage stopped exactly on the trip
    // point trips despite rounding in the mm <-> step conversion.
    constexpr double kEpsilon_m = 0.5e-6;
    bool now = triggered_;
    if (min_side_) {
        if (!triggered_ && position_m <= trip_m_ + kEpsilon_m) now = true;
        if (triggered_ && position_m > trip_m_ + hysteresis_m_ + kEpsilon_m) now = false;
    } else {
        if (!triggered_ && position_m >= trip_m_ - kEpsilon_m) now = true;
        if (triggered_ && position_m < trip_m_ - hysteresis_m_ - kEpsilon_m) now = false;
    }
    if (now == triggered_) return;
    triggered_ = now;
    if (now) ++trips_;
    set_contact(contact_closed());
}

void LimitSwitch::set_contact(bool closed) {
    const std::uint64_t generation = ++bounce_generation_;
    if (bounce_s_ <= 0 || bounce_edges_ == 0) {
        apply_contact(closed);
        return;
    }
    // Bounce: the contact chatters between the old and new state at times
    // drawn from the seeded generator within the bounce window, then settles.
    // Raw engine output keeps the sequence identical on every platform
    // (std:: distributions are implementation-defined).
    const Cycle window = static_cast<Cycle>(std::llround(bounce_s_ * clock().frequency_hz()));
    const unsigned pairs = 1 + static_cast<unsigned>(rng_() % bounce_edges_);
    std::vector<Cycle> offsets;
    for (unsigned i = 0; i < 2 * pairs; ++i) offsets.push_back(window > 1 ? rng_() % window : 0);
    std::sort(offsets.begin(), offsets.end());
    apply_contact(closed);
    const Cycle start = clock().cycle();
    bool state = closed;
    for (Cycle offset : offsets) {
        state = !state;
        const bool level = state;
        clock().scheduler().at(start + offset, [this, generation, level](Cycle) {
            if (generation == bounce_generation_) apply_contact(level);
        });
    }
    clock().scheduler().at(start + window, [this, generation, closed](Cycle) {
        if (generation == bounce_generation_) apply_contact(closed);
    });
}

void LimitSwitch::apply_contact(bool closed) {
    if (applied_once_ && closed != applied_closed_) ++contact_transitions_;
    applied_once_ = true;
    applied_closed_ = closed;
    publish(sig_closed_, closed ? 1 : 0);
    if (closed) {
        drive_output(out_pin_, closed_level_);
    } else if (pull_ == "internal_up" || pull_ == "none") {
        // The MCU pin decides: its pull-up if the firmware enabled it, else floating (reads 0).
        release_output(out_pin_);
    } else if (pull_ == "push_pull") {
        drive_output(out_pin_, !closed_level_);
    } else {
        pull_output(out_pin_, pull_ == "external_up", pull_ohm_);
    }
}

}  // namespace avrbench
