// A generic low-side switch array: per channel one NPN transistor (or
// N-MOSFET) between a load and ground, driven by a logic input through its
// base (gate) resistor, with a flyback diode across the load. Seed 001 §3.2:
// the unipolar drive board switches each half-winding this way, centre tap to
// the supply, "a reverse-biased flyback diode across each coil".
//
// The load side is electrical: a motor part asks for the drive of the
// half-winding on a channel (winding()) and is told when it changes.
//   switch on:  v = V_supply - V_sat - (R_on + R_series) * i   (current from the supply)
//   switch off: the current freewheels through the flyback diode across the
//               winding, v = -V_f, until it reaches zero; no reverse current.
#pragma once

#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/WindingDrive.hpp"

namespace avrbench {

class LowSideSwitch final : public Part, public DriveSource {
public:
    static std::vector<ParamSpec> param_specs();

    LowSideSwitch(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "low_side_switch"; }
    void start() override;

    int channels() const { return static_cast<int>(in_pins_.size()); }
    // Channel 1..channels(): the transistor conducts.
    bool on(int channel) const;
    // The drive of a winding from a supply of `supply_v` to this channel, with
    // `series_ohm` more in the switched path (a sense resistor).
    WindingDrive winding(int channel, double supply_v, double series_ohm) const;
    WindingDrive winding_at(const WindingTap& tap) const override {
        return winding(tap.minus, tap.supply_v, tap.series_ohm);
    }
    std::string tap_problem(const WindingTap& tap) const override;

private:
    void on_input(std::size_t pin, bool level) override;

    std::vector<std::size_t> in_pins_;
    std::vector<std::size_t> sig_on_;
    bool active_high_;
    double v_sat_, r_on_, v_flyback_;
};

}  // namespace avrbench
