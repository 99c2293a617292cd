// A plotter's pen on a servo (seed 002's SG90 header): port `horn` requires
// the servo, ports `x` and `y` the two linear axes' carriages. The pen is down
// while the horn is at or beyond `down_angle`; while down, every carriage move
// adds to the current stroke, so the drawing is a trace (`down`, and the pen
// tip's `tip_x_mm` / `tip_y_mm`) and a list of polylines for checks. It
// provides port `tool` (the pen's contact) for a motion_oracle.
#pragma once

#include <vector>

#include "parts/Carriage.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ServoHorn.hpp"
#include "parts/ToolContact.hpp"

namespace avrbench {


class PenLift final : public Part, public ToolContact {
public:
    static std::vector<ParamSpec> param_specs();

    PenLift(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "pen_lift"; }
    void start() override;
    std::string summary() override;

    struct Point {
        double x_mm, y_mm;
    };
    bool down() const { return down_; }
    bool tool_down() const override { return down_; }
    // Every stroke drawn: the tip's positions from pen down to pen up.
    const std::vector<std::vector<Point>>& strokes() const { return strokes_; }

private:
    void connect_carriage(Carriage*& slot, Carriage& axis);
    void tick();
    void on_carriage();
    void set_down(bool down);

    ServoHorn* servo_ = nullptr;
    Carriage* x_ = nullptr;
    Carriage* y_ = nullptr;
    double down_angle_deg_;
    Cycle sample_cycles_;
    bool down_ = false;
    std::vector<std::vector<Point>> strokes_;
    std::size_t sig_down_, sig_x_, sig_y_;
};

}  // namespace avrbench
