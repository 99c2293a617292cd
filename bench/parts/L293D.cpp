#include "parts/L293D.hpp"

#include "parts/PartRegistry.hpp"

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(L293D, "l293d");

std::vector<ParamSpec> L293D::param_specs() {
    using PT = ParamType;
    return {
        {.name = "supply", .type = PT::Quantity, .dimension = Dimension::Voltage, .default_value = "12V",
         .source = "seed 003 §2.1: motor supply V_CC2 = 12 VDC", .help = "V_CC2, the motor supply"},
        {.name = "v_drop_high", .type = PT::Quantity, .dimension = Dimension::Voltage, .default_value = "1.4V",
         .source = "TI SLRS008C electrical characteristics: V_OH = V_CC2 - 1.4 V typ at -0.6 A",
         .help = "drop of a high output sourcing current"},
        {.name = "v_drop_low", .type = PT::Quantity, .dimension = Dimension::Voltage, .default_value = "1.2V",
         .source = "TI SLRS008C: V_OL = 1.2 V typ at 0.6 A", .help = "drop of a low output sinking current"},
        {.name = "v_clamp", .type = PT::Quantity, .dimension = Dimension::Voltage, .default_value = "1.3V",
         .source = "TI SLRS008C: V_OKH = V_CC2 + 1.3 V, V_OKL = 1.3 V typ at 0.6 A",
         .help = "clamp diode forward voltage"},
        {.name = "r_out", .type = PT::Quantity, .dimension = Dimension::Resistance, .default_value = "0ohm",
         .source = "assumed: drops taken as constant (the datasheet gives them at 0.6 A only)",
         .help = "extra resistance per conducting output"},
        {.name = "enable_unconnected", .type = PT::Choice, .default_value = "high", .choices = {"high", "low"},
         .help = "level of an EN input with no net (boards often tie EN to 5 V)"},
    };
}

L293D::L293D(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      enable_unconnected_(params.text("enable_unconnected") == "high"),
      supply_v_(params.quantity("supply")),
      drop_high_v_(params.quantity("v_drop_high")),
      drop_low_v_(params.quantity("v_drop_low")),
      clamp_v_(params.quantity("v_clamp")),
      r_out_ohm_(params.quantity("r_out")) {
    if (supply_v_ < 4.5 || supply_v_ > 36) {
        throw part_error(this->name(), "supply must be within the L293D's 4.5..36 V");
    }
    en_pins_[0] = add_pin("en12", TerminalRole::Input);
    en_pins_[1] = add_pin("en34", TerminalRole::Input);
    for (int i = 0; i < 4; ++i) in_pins_[i] = add_pin("in" + std::to_string(i + 1), TerminalRole::Input);
    // 1 = high, 0 = low, 0.5 = off (high impedance).
    for (int i = 0; i < 4; ++i) sig_out_[i] = add_signal("out" + std::to_string(i + 1), true, 0.5);
    provide_port<DriveSource>("windings", *this, "a bipolar motor's windings between pairs of outputs 1Y..4Y");
}

std::string L293D::tap_problem(const WindingTap& tap) const {
    for (const int output : {tap.plus, tap.minus}) {
        if (output < 1 || output > 4) return "L293D outputs are 1..4, not " + std::to_string(output);
    }
    if (tap.plus == tap.minus) return "a winding needs two different outputs";
    return {};
}

void L293D::start() { publish_outputs(); }

bool L293D::enabled(int channel) const {
    const std::size_t pin = en_pins_[channel <= 2 ? 0 : 1];
    return connected(pin) ? input_level(pin) : enable_unconnected_;
}

L293D::Output L293D::output(int channel) const {
    if (!enabled(channel)) return Output::Off;
    return input_level(in_pins_[channel - 1]) ? Output::High : Output::Low;
}

// Voltage of one output terminal when the winding current leaves through it
// into the winding (`current_leaves`) or enters it from the winding.
double L293D::terminal_v(Output out, bool current_leaves) const {
    switch (out) {
        case Output::High: return current_leaves ? supply_v_ - drop_high_v_ : supply_v_ + clamp_v_;
        case Output::Low: return current_leaves ? -clamp_v_ : drop_low_v_;
        case Output::Off: return current_leaves ? -clamp_v_ : supply_v_ + clamp_v_;
    }
    return 0;
}

WindingDrive L293D::winding(int plus, int minus) const {
    const Output p = output(plus), n = output(minus);
    WindingDrive d;
    // i > 0 leaves `plus` and enters `minus`; i < 0 the other way round.
    d.v_pos = terminal_v(p, true) - terminal_v(n, false);
    d.v_neg = terminal_v(p, false) - terminal_v(n, true);
    d.r_pos = d.r_neg = 2 * r_out_ohm_;
    if (p == Output::High && n == Output::Low) d.polarity = 1;
    if (p == Output::Low && n == Output::High) d.polarity = -1;
    return d;
}

void L293D::publish_outputs() {
    for (int c = 1; c <= 4; ++c) {
        const Output o = output(c);
        publish(sig_out_[c - 1], o == Output::High ? 1.0 : o == Output::Low ? 0.0 : 0.5);
    }
}

void L293D::on_input(std::size_t, bool) {
    publish_outputs();
    notify_drive_change();
}

}  // namespace avrbench
