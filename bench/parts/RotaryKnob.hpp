// A rotary encoder knob with a push button (an Alps EC11-type part on a
// printer's display board): A and B contacts and the button close to GND
// (the MCU's pull-ups make the open level), A leading B for a clockwise
// turn (00 -> 10 -> 11 -> 01 -> 00 as contacts closed = 1). A detent is
// `transitions_per_detent` quadrature transitions, made `turn_rate` detents
// per second. Actions: press, release, turn(detents; negative = the other
// way). Button bounce is not modelled.
#pragma once

#include <cstdint>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class RotaryKnob final : public Part {
public:
    static std::vector<ParamSpec> param_specs();
    RotaryKnob(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "rotary_knob"; }
    void start() override;
    std::string summary() override;

    std::vector<Action> actions() const override;
    void act(const std::string& action, const std::vector<double>& arguments) override;

    void press();
    void release();
    // Queues `detents` detents (negative: counter-clockwise) after those still turning.
    void turn(int detents);
    bool pressed() const { return pressed_; }
    std::int64_t position() const { return position_; }  // transitions made, + clockwise

private:
    void step_transition(Cycle scheduled);
    void drive_contacts();

    std::size_t a_pin_, b_pin_, button_pin_;
    unsigned transitions_per_detent_;
    Cycle transition_cycles_;
    bool pressed_ = false;
    unsigned phase_ = 0;           // 0..3 along 00, 10, 11, 01 (A, B closed)
    std::int64_t position_ = 0;
    std::int64_t pending_ = 0;     // transitions still to make, signed
    bool turning_ = false;
    std::uint64_t presses_ = 0;
    std::size_t sig_position_, sig_button_;
};

}  // namespace avrbench
