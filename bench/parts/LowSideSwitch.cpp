#include "parts/LowSideSwitch.hpp"

#include "parts/PartRegistry.hpp"

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(LowSideSwitch, "low_side_switch");

std::vector<ParamSpec> LowSideSwitch::param_specs() {
    using PT = ParamType;
    return {
        {.name = "channels", .type = PT::Integer, .default_value = "4",
         .source = "seed 001 §3.2: four half-windings A, B, C, D",
         .help = "number of switches (1..8), inputs in1..inN", .min = 1, .max = 8},
        {.name = "active", .type = PT::Choice, .default_value = "high", .choices = {"high", "low"},
         .source = "seed 001 Fig. 3.1: NPN with a base resistor (input high = on)",
         .help = "input level that turns a switch on"},
        {.name = "v_sat", .type = PT::Quantity, .dimension = Dimension::Voltage, .default_value = "0.3V",
         .source = "assumed: a small-signal NPN's V_CE(sat) at a few hundred mA (seed 001 names no part)",
         .help = "saturation voltage of a conducting switch"},
        {.name = "r_on", .type = PT::Quantity, .dimension = Dimension::Resistance, .default_value = "0ohm",
         .source = "assumed (use it for a MOSFET's R_DS(on))", .help = "on resistance"},
        {.name = "v_flyback", .type = PT::Quantity, .dimension = Dimension::Voltage, .default_value = "0.8V",
         .source = "assumed: a 1N400x's forward voltage at a few hundred mA", .help = "flyback diode forward voltage"},
    };
}

LowSideSwitch::LowSideSwitch(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      active_high_(params.text("active") == "high"),
      v_sat_(params.quantity("v_sat")),
      r_on_(params.quantity("r_on")),
      v_flyback_(params.quantity("v_flyback")) {
    const long long n = params.integer("channels");
    if (n < 1 || n > 8) throw part_error(this->name(), "channels must be 1..8");
    for (long long i = 1; i <= n; ++i) {
        in_pins_.push_back(add_pin("in" + std::to_string(i), TerminalRole::Input));
        sig_on_.push_back(add_signal("on" + std::to_string(i), false));
    }
    provide_port<DriveSource>("windings", *this, "a unipolar motor's half-windings, one per channel");
}

std::string LowSideSwitch::tap_problem(const WindingTap& tap) const {
    if (tap.minus < 1 || tap.minus > channels()) {
        return "coil channel " + std::to_string(tap.minus) + " is not a channel of '" + name() + "' (1.." +
               std::to_string(channels()) + ")";
    }
    return {};
}

void LowSideSwitch::start() {
    for (int c = 1; c <= channels(); ++c) publish(sig_on_[c - 1], on(c) ? 1 : 0);
}

bool LowSideSwitch::on(int channel) const {
    const std::size_t pin = in_pins_[channel - 1];
    // An unconnected input: the base resistor pulls nothing, the switch is off.
    if (!connected(pin)) return false;
    return input_level(pin) == active_high_;
}

WindingDrive LowSideSwitch::winding(int channel, double supply_v, double series_ohm) const {
    WindingDrive d;
    d.v_neg = WindingDrive::kNoPath;  // neither the transistor nor the diode conducts backwards
    if (on(channel)) {
        d.v_pos = supply_v - v_sat_;
        d.r_pos = r_on_ + series_ohm;
        d.polarity = 1;
    } else {
        d.v_pos = -v_flyback_;
        d.polarity = 0;
    }
    return d;
}

void LowSideSwitch::on_input(std::size_t pin, bool) {
    for (std::size_t i = 0; i < in_pins_.size(); ++i) {
        if (in_pins_[i] == pin) publish(sig_on_[i], on(static_cast<int>(i) + 1) ? 1 : 0);
    }
    notify_drive_change();
}

}  // namespace avrbench
