#include "parts/RotaryKnob.hpp"

#include <cmath>
#include <cstdio>

#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(RotaryKnob, "rotary_knob");

std::vector<ParamSpec> RotaryKnob::param_specs() {
    using PT = ParamType;
    return {
        {.name = "transitions_per_detent", .type = PT::Integer, .default_value = "4",
         .source = "Prusa-Firmware Configuration.h ENCODER_PULSES_PER_STEP 4: a full quadrature cycle per detent",
         .help = "quadrature transitions between two detents (4: one cycle, 2: half a cycle)", .min = 1, .max = 4},
        {.name = "turn_rate", .type = PT::Quantity, .dimension = Dimension::Frequency, .default_value = "10Hz",
         .source = "assumed: a hand turning the knob briskly, 10 detents per second",
         .help = "detents per second a turn action makes", .min = 0.1, .max = 1000},
    };
}

RotaryKnob::RotaryKnob(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    transitions_per_detent_ = static_cast<unsigned>(params.integer("transitions_per_detent"));
    const double rate = params.quantity("turn_rate");
    transition_cycles_ = std::max<Cycle>(1, clock.cycles_from_seconds(1.0 / (rate * transitions_per_detent_)));
    a_pin_ = add_pin("a", TerminalRole::Output);
    b_pin_ = add_pin("b", TerminalRole::Output);
    button_pin_ = add_pin("button", TerminalRole::Output);
    sig_position_ = add_signal("position", true, 0);
    sig_button_ = add_signal("pressed", false, 0);
    add_readout("detents", [this] { return static_cast<double>(position_ / static_cast<std::int64_t>(transitions_per_detent_)); });
}

void RotaryKnob::start() {
    drive_contacts();
    release_output(button_pin_);
}

// Contacts closed to GND drive low; open ones are left to the pull-ups.
void RotaryKnob::drive_contacts() {
    static constexpr bool kAClosed[4] = {false, true, true, false};
    static constexpr bool kBClosed[4] = {false, false, true, true};
    if (kAClosed[phase_]) drive_output(a_pin_, false); else release_output(a_pin_);
    if (kBClosed[phase_]) drive_output(b_pin_, false); else release_output(b_pin_);
}

std::vector<Part::Action> RotaryKnob::actions() const {
    return {{"press", 0, "close the push button"},
            {"release", 0, "open the push button"},
            {"turn", 1, "turn by N detents (negative: counter-clockwise) at turn_rate"}};
}

void RotaryKnob::act(const std::string& action, const std::vector<double>& arguments) {
    const auto expect = [&](std::size_t n) {
        if (arguments.size() != n) {
            throw part_error(name(), "'" + action + "' takes " + std::to_string(n) + " argument" + (n == 1 ? "" : "s"));
        }
    };
    if (action == "press") {
        expect(0);
        press();
    } else if (action == "release") {
        expect(0);
        release();
    } else if (action == "turn") {
        expect(1);
        const double d = arguments[0];
        if (d != std::floor(d) || std::fabs(d) > 1e6) throw part_error(name(), "turn takes a whole number of detents");
        turn(static_cast<int>(d));
    } else {
        Part::act(action, arguments);
    }
}

void RotaryKnob::press() {
    if (!pressed_) ++presses_;
    pressed_ = true;
    drive_output(button_pin_, false);
    publish(sig_button_, 1);
}

void RotaryKnob::release() {
    pressed_ = false;
    release_output(button_pin_);
    publish(sig_button_, 0);
}

void RotaryKnob::turn(int detents) {
    pending_ += static_cast<std::int64_t>(detents) * transitions_per_detent_;
    if (!turning_ && pending_ != 0) {
        turning_ = true;
        clock().scheduler().at(clock().cycle() + transition_cycles_, [this](Cycle c) { step_transition(c); });
    }
}

void RotaryKnob::step_transition(Cycle scheduled) {
    if (pending_ == 0) {
        turning_ = false;
        return;
    }
    const int dir = pending_ > 0 ? 1 : -1;
    pending_ -= dir;
    phase_ = static_cast<unsigned>((phase_ + (dir > 0 ? 1 : 3)) % 4);
    position_ += dir;
    drive_contacts();
    publish(sig_position_, static_cast<double>(position_));
    note_activity();
    if (pending_ != 0) {
        clock().scheduler().at(scheduled + transition_cycles_, [this](Cycle c) { step_transition(c); });
    } else {
        turning_ = false;
    }
}

std::string RotaryKnob::summary() {
    char text[120];
    std::snprintf(text, sizeof text, "knob       %s: %lld detents from the start, %llu presses%s", name().c_str(),
                  static_cast<long long>(position_ / static_cast<std::int64_t>(transitions_per_detent_)),
                  static_cast<unsigned long long>(presses_), pressed_ ? ", held" : "");
    return text;
}

}  // namespace avrbench
