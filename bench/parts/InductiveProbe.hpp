// An inductive bed probe (Prusa's PINDA): its output changes when the
// nozzle is at or below `trigger_height` above the bed under the probe, the
// probe sitting at (offset_x, offset_y) from the nozzle. The bed's surface
// is a height map: a grid of heights over the bed, bilinear between points,
// so mesh levelling has something to measure. The carriages' positions are
// the machine's: X and Y from 0 at their min ends, Z the nozzle's height
// above a flat bed at 0.
#pragma once

#include <vector>

#include "parts/Carriage.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class InductiveProbe final : public Part {
public:
    static std::vector<ParamSpec> param_specs();
    InductiveProbe(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "inductive_probe"; }
    void start() override;

    bool triggered() const { return triggered_; }
    unsigned triggers() const { return triggers_; }
    // The bed's height (m) at machine position (x, y) in metres.
    double bed_height_m(double x_m, double y_m) const;

private:
    void update();
    void apply_output();

    Carriage *x_ = nullptr, *y_ = nullptr, *z_ = nullptr;
    std::size_t out_pin_;
    double offset_x_m_, offset_y_m_, trigger_m_, hysteresis_m_;
    double bed_x_m_, bed_y_m_;
    std::vector<std::vector<double>> heights_m_;  // [row along y][column along x]
    bool active_high_;
    bool triggered_ = false;
    unsigned triggers_ = 0;
    std::size_t sig_triggered_, sig_gap_;
};

}  // namespace avrbench
