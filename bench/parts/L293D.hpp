// The L293D quadruple half-H driver (TI SLRS008C; ST L293D): four push-pull
// outputs 1Y..4Y with clamp diodes, inputs 1A..4A, enables 1,2EN and 3,4EN.
// Truth table (SLRS008C "Function table"): EN = H: Y = A; EN = L: Y = Z.
//
// The outputs are electrical, not logic: a motor part asks for the drive of a
// winding wired between two outputs (winding()) and is told when it changes.
// Output voltages (datasheet "electrical characteristics", typical, at 0.6 A):
//   driven high, sourcing:  V_CC2 - 1.4 V (V_OH);   driven low, sinking: 1.2 V (V_OL)
//   current forced into a high or off output: V_CC2 + 1.3 V (upper clamp, V_OKH)
//   current forced out of a low or off output: -1.3 V (lower clamp, V_OKL)
// so an output at Z conducts only through its clamp diodes (fast decay into
// the supply) and both outputs low short the winding through one transistor
// and one diode (slow decay).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/WindingDrive.hpp"

namespace avrbench {

class L293D final : public Part, public DriveSource {
public:
    enum class Output { Low, High, Off };

    static std::vector<ParamSpec> param_specs();

    L293D(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "l293d"; }
    void start() override;

    // Output 1..4 (1Y..4Y).
    Output output(int channel) const;
    // The drive of a winding wired from output `plus` to output `minus`.
    WindingDrive winding(int plus, int minus) const;
    WindingDrive winding_at(const WindingTap& tap) const override { return winding(tap.plus, tap.minus); }
    std::string tap_problem(const WindingTap& tap) const override;
    double supply_v() const { return supply_v_; }

private:
    void on_input(std::size_t pin, bool level) override;
    bool enabled(int channel) const;
    double terminal_v(Output out, bool current_leaves) const;
    void publish_outputs();

    std::size_t en_pins_[2];
    std::size_t in_pins_[4];
    bool enable_unconnected_;
    double supply_v_, drop_high_v_, drop_low_v_, clamp_v_, r_out_ohm_;
    std::size_t sig_out_[4];
};

}  // namespace avrbench
