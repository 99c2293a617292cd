// The 74HC595 8-bit shift register with output latches (NXP 74HC595 data
// sheet, "Functional description"): on a rising SRCLK (SHCP) edge the shift
// register takes SER (DS) into stage 0 and moves every stage up by one; on a
// rising RCLK (STCP) edge the storage register takes the shift register;
// outputs Q0..Q7 show the storage register while OE is low and are high
// impedance while it is high; SRCLR (MR) low clears the shift register
// (asynchronously). Q7S is stage 7, for daisy-chaining.
//
// Bytes sent MSB first (the Adafruit Motor Shield v1's latch_tx(), seed 003
// digest §2.4) therefore end with bit n on Qn.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class ShiftRegister595 final : public Part {
public:
    static std::vector<ParamSpec> param_specs();

    ShiftRegister595(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "shift_register_595"; }
    void start() override;

    std::uint8_t shift_register() const { return shift_; }
    std::uint8_t storage_register() const { return storage_; }
    bool outputs_enabled() const;
    std::uint64_t latches() const { return latches_; }

private:
    void on_input(std::size_t pin, bool level) override;
    void drive_outputs();

    std::size_t ser_, srclk_, rclk_, oe_, srclr_;
    std::size_t q_[8];
    std::size_t q7s_;
    bool oe_unconnected_low_, srclr_unconnected_high_;
    std::uint8_t shift_ = 0, storage_ = 0;
    std::uint64_t latches_ = 0;
    std::size_t sig_shift_, sig_storage_, sig_oe_;
};

}  // namespace avrbench
