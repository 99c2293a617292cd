#include "parts/InductiveProbe.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/Errors.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(InductiveProbe, "inductive_probe");

std::vector<ParamSpec> InductiveProbe::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "offset_x", .type = PT::Quantity, .dimension = D::Length, .default_value = "0mm",
         .source = "the printer's probe offset (Prusa MK3S: X_PROBE_OFFSET_FROM_EXTRUDER 23 mm)",
         .help = "probe position from the nozzle along X", .min = -1, .max = 1},
        {.name = "offset_y", .type = PT::Quantity, .dimension = D::Length, .default_value = "0mm",
         .source = "the printer's probe offset (Prusa MK3S: Y_PROBE_OFFSET_FROM_EXTRUDER 5 mm)",
         .help = "probe position from the nozzle along Y", .min = -1, .max = 1},
        {.name = "trigger_height", .type = PT::Quantity, .dimension = D::Length, .default_value = "1mm",
         .source = "assumed: the nozzle's height above the sheet where a PINDA switches (calibrated per printer)",
         .help = "the nozzle height above the bed under the probe at which the output switches", .min = 0, .max = 0.1},
        {.name = "hysteresis", .type = PT::Quantity, .dimension = D::Length, .default_value = "0.02mm",
         .source = "assumed", .help = "how much higher the nozzle must go before the output switches back", .min = 0, .max = 0.01},
        {.name = "bed_size_x", .type = PT::Quantity, .dimension = D::Length, .default_value = "250mm",
         .source = "assumed: a 250 x 210 mm sheet (Prusa MK3S)", .help = "the height map's extent along X from 0", .min = 1e-3, .max = 10},
        {.name = "bed_size_y", .type = PT::Quantity, .dimension = D::Length, .default_value = "210mm",
         .source = "assumed: a 250 x 210 mm sheet (Prusa MK3S)", .help = "the height map's extent along Y from 0", .min = 1e-3, .max = 10},
        {.name = "bed_heights", .type = PT::Text, .default_value = "0",
         .help = "the bed's heights in mm on a grid: rows from Y = 0 to bed_size_y separated by '/', each row's values "
                 "from X = 0 to bed_size_x separated by spaces (\"0 0.1 / 0.05 0.15\"); one value: a flat bed"},
        {.name = "active", .type = PT::Choice, .default_value = "high", .choices = {"high", "low"},
         .source = "Prusa MK3S: Z_MIN_ENDSTOP_INVERTING 0 (variants/MK3S.h), the PINDA reads high when triggered",
         .help = "output level while triggered (push-pull)"},
    };
}

InductiveProbe::InductiveProbe(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    offset_x_m_ = params.quantity("offset_x");
    offset_y_m_ = params.quantity("offset_y");
    trigger_m_ = params.quantity("trigger_height");
    hysteresis_m_ = params.quantity("hysteresis");
    bed_x_m_ = params.quantity("bed_size_x");
    bed_y_m_ = params.quantity("bed_size_y");
    active_high_ = params.text("active") == "high";
    std::stringstream rows(params.text("bed_heights"));
    std::string row_text;
    std::size_t columns = 0;
    while (std::getline(rows, row_text, '/')) {
        std::stringstream values(row_text);
        std::vector<double> row;
        for (std::string v; values >> v;) {
            char* end = nullptr;
            const double mm = std::strtod(v.c_str(), &end);
            if (end == v.c_str() || *end != '\0' || !std::isfinite(mm) || std::abs(mm) > 100) {
                throw part_error(this->name(), "bed_heights: '" + v + "' is not a height in mm (-100..100)");
            }
            row.push_back(mm / 1000.0);
        }
        if (row.empty()) throw part_error(this->name(), "bed_heights: an empty row");
        if (columns != 0 && row.size() != columns) throw part_error(this->name(), "bed_heights: rows of different lengths");
        columns = row.size();
        heights_m_.push_back(std::move(row));
    }
    if (heights_m_.empty()) throw part_error(this->name(), "bed_heights: no values");
    out_pin_ = add_pin("out", TerminalRole::Output);
    sig_triggered_ = add_signal("triggered", false, 0);
    sig_gap_ = add_signal({.name = "gap_mm", .real = true, .unit = "mm"}, 0);
    require_port<Carriage>("x", false, "the X axis (the probe's X is the carriage's plus offset_x)",
                           [this](Carriage& c) { x_ = &c; c.on_move([this](double) { update(); }); });
    require_port<Carriage>("y", false, "the Y axis (the bed's Y position under the probe)",
                           [this](Carriage& c) { y_ = &c; c.on_move([this](double) { update(); }); });
    require_port<Carriage>("z", true, "the Z axis (the nozzle's height)",
                           [this](Carriage& c) { z_ = &c; c.on_move([this](double) { update(); }); });
    add_readout("triggers", [this] { return static_cast<double>(triggers_); });
}

// Bilinear over the grid; outside it, the nearest edge's height.
double InductiveProbe::bed_height_m(double x_m, double y_m) const {
    const std::size_t rows = heights_m_.size(), cols = heights_m_[0].size();
    const auto position = [](double v, double size, std::size_t n, std::size_t& i, double& f) {
        if (n == 1) {
            i = 0;
            f = 0;
            return;
        }
        const double u = std::clamp(v / size, 0.0, 1.0) * static_cast<double>(n - 1);
        i = std::min(static_cast<std::size_t>(u), n - 2);
        f = u - static_cast<double>(i);
    };
    std::size_t c = 0, r = 0;
    double fx = 0, fy = 0;
    position(x_m, bed_x_m_, cols, c, fx);
    position(y_m, bed_y_m_, rows, r, fy);
    const auto h = [&](std::size_t rr, std::size_t cc) { return heights_m_[std::min(rr, rows - 1)][std::min(cc, cols - 1)]; };
    const double low = h(r, c) * (1 - fx) + h(r, c + 1) * fx;
    const double high = h(r + 1, c) * (1 - fx) + h(r + 1, c + 1) * fx;
    return low * (1 - fy) + high * fy;
}

void InductiveProbe::start() {
    update();
    apply_output();
}

void InductiveProbe::update() {
    if (z_ == nullptr) return;
    const double x = (x_ != nullptr ? x_->position_mm() / 1000.0 : 0) + offset_x_m_;
    const double y = (y_ != nullptr ? y_->position_mm() / 1000.0 : 0) + offset_y_m_;
    const double gap = z_->position_mm() / 1000.0 - bed_height_m(x, y);
    publish(sig_gap_, gap * 1000.0);
    const bool triggered = triggered_ ? gap <= trigger_m_ + hysteresis_m_ : gap <= trigger_m_;
    if (triggered == triggered_) return;
    triggered_ = triggered;
    if (triggered) ++triggers_;
    publish(sig_triggered_, triggered ? 1 : 0);
    apply_output();
}

void InductiveProbe::apply_output() { drive_output(out_pin_, triggered_ == active_high_); }

}  // namespace avrbench
