// A hall-effect endstop: a sensor at a fixed place along an axis and a magnet
// on the carriage (port `axis` requires a linear axis' `carriage`). The
// magnet's field at the sensor falls with the distance d between them as a
// dipole's on its axis, B(d) = B0 / (1 + (d/d0)^2)^1.5. Two outputs, as the
// two kinds of sensor:
//  - `out`, open drain (an Allegro A3144-class switch): pulled low while the
//    field is above the operate point, released below the release point
//    (hysteresis); the net needs a pull-up (the MCU's or a resistor);
//  - `analog`, an analog voltage (an Allegro A1324-class linear sensor):
//    supply/2 + sensitivity x B, clamped to the output's range, which an ADC
//    pin samples.
#pragma once

#include "parts/Carriage.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class HallEndstop final : public Part {
public:
    static std::vector<ParamSpec> param_specs();

    HallEndstop(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "hall_endstop"; }
    void start() override;
    std::string summary() override;

    // The magnet's field at the sensor now (G) and the analog output (V).
    double field_G() const;
    double analog_volts_now() const;
    bool switched_on() const { return on_; }
    unsigned trips() const { return trips_; }

private:
    void connect_axis(Carriage& axis);
    void update();

    Carriage* axis_ = nullptr;
    double sensor_mm_, b0_G_, d0_mm_, operate_G_, release_G_, supply_v_, sensitivity_v_per_G_;
    std::size_t out_pin_;
    std::size_t sig_field_ = 0, sig_on_ = 0;
    bool on_ = false;
    unsigned trips_ = 0;
};

}  // namespace avrbench
