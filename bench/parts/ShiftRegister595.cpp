#include "parts/ShiftRegister595.hpp"

#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(ShiftRegister595, "shift_register_595");

std::vector<ParamSpec> ShiftRegister595::param_specs() {
    using PT = ParamType;
    return {
        {.name = "oe_unconnected", .type = PT::Choice, .default_value = "low", .choices = {"low", "high"},
         .help = "level of OE with no net (low: outputs enabled)"},
        {.name = "srclr_unconnected", .type = PT::Choice, .default_value = "high", .choices = {"high", "low"},
         .source = "boards usually tie MR to V_CC", .help = "level of SRCLR with no net"},
    };
}

ShiftRegister595::ShiftRegister595(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      oe_unconnected_low_(params.text("oe_unconnected") == "low"),
      srclr_unconnected_high_(params.text("srclr_unconnected") == "high") {
    ser_ = add_pin("ser", TerminalRole::Input);
    srclk_ = add_pin("srclk", TerminalRole::Input);
    rclk_ = add_pin("rclk", TerminalRole::Input);
    oe_ = add_pin("oe", TerminalRole::Input);
    srclr_ = add_pin("srclr", TerminalRole::Input);
    for (int i = 0; i < 8; ++i) q_[i] = add_pin("q" + std::to_string(i), TerminalRole::Output);
    q7s_ = add_pin("q7s", TerminalRole::Output);
    sig_shift_ = add_signal("shift", true);
    sig_storage_ = add_signal("outputs", true);
    sig_oe_ = add_signal("outputs_enabled", false);
}

bool ShiftRegister595::outputs_enabled() const {
    return connected(oe_) ? !input_level(oe_) : oe_unconnected_low_;
}

void ShiftRegister595::start() {
    drive_outputs();
    drive_output(q7s_, false);
}

void ShiftRegister595::drive_outputs() {
    const bool enabled = outputs_enabled();
    publish(sig_oe_, enabled ? 1 : 0);
    for (int i = 0; i < 8; ++i) {
        if (enabled) {
            drive_output(q_[i], ((storage_ >> i) & 1) != 0);
        } else {
            release_output(q_[i]);
        }
    }
}

void ShiftRegister595::on_input(std::size_t pin, bool level) {
    const bool srclr_high = connected(srclr_) ? input_level(srclr_) : srclr_unconnected_high_;
    if (pin == srclk_ && level && srclr_high) {
        shift_ = static_cast<std::uint8_t>((shift_ << 1) | (input_level(ser_) ? 1 : 0));
        drive_output(q7s_, (shift_ & 0x80) != 0);
        publish(sig_shift_, shift_);
    } else if (pin == srclr_ && !level) {
        shift_ = 0;
        drive_output(q7s_, false);
        publish(sig_shift_, shift_);
    } else if (pin == rclk_ && level) {
        storage_ = shift_;
        ++latches_;
        publish(sig_storage_, storage_);
        drive_outputs();
    } else if (pin == oe_) {
        drive_outputs();
    }
}

}  // namespace avrbench
