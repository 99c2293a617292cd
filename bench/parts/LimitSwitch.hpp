// A limit (end-stop) switch on an axis (port `axis` requires a linear
// axis' `carriage`): trips at a position with hysteresis;
// NO or NC contact switched to GND or VCC; the level of the open contact comes
// from a pull-up (the MCU's internal one, as the firmware sets it, or an
// external resistor) or pull-down; optional contact bounce, deterministic from
// a seed.
#pragma once

#include <cstdint>
#include <random>

#include "parts/Carriage.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class LimitSwitch final : public Part {
public:
    static std::vector<ParamSpec> param_specs();

    LimitSwitch(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "limit_switch"; }

    bool triggered() const { return triggered_; }
    bool contact_closed() const;
    unsigned trips() const { return trips_; }
    // Make/break transitions of the contact, bounce included.
    unsigned contact_transitions() const { return contact_transitions_; }

    void start() override;
    // stuck_closed: the contact is closed wherever the carriage is (a
    // shorted or jammed switch, or a finger on it); stuck_open: never closes
    // (a broken wire); none: the carriage decides again.
    std::vector<std::string> fault_names() const override { return {"stuck_closed", "stuck_open"}; }
    void apply_fault(const std::string& fault) override;

private:
    void connect_axis(Carriage& axis);
    void on_axis_move(double position_m);
    void set_contact(bool closed);
    void apply_contact(bool closed);

    Carriage* axis_ = nullptr;
    bool position_given_;
    double position_m_;  // the trip position as given (default: the side's end)
    std::size_t out_pin_;
    bool min_side_;
    double trip_m_ = 0, hysteresis_m_;
    bool normally_open_;
    bool closed_level_;        // the output level with the contact closed
    std::string pull_;         // internal_up | external_up | external_down | none | push_pull
    double pull_ohm_;          // the external pull resistor
    double bounce_s_;
    unsigned bounce_edges_;
    std::mt19937_64 rng_;
    bool triggered_ = false;
    unsigned trips_ = 0;
    unsigned contact_transitions_ = 0;
    bool applied_closed_ = false;
    bool applied_once_ = false;
    std::uint64_t bounce_generation_ = 0;
    std::size_t sig_closed_;
};

}  // namespace avrbench
