#include "parts/PenLift.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
#include <cstdio>

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(PenLift, "pen_lift");

std::vector<ParamSpec> PenLift::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "down_angle", .type = PT::Quantity, .dimension = D::Angle, .default_value = "135deg",
         .source = "assumed: seed 002's pen is down at +90 deg of its -90/0/+90 positions (servo 180 deg) and up at 0 (90 deg); halfway between",
         .help = "the horn angle (servo degrees) from which the pen touches the paper"},
        {.name = "sample_interval", .type = PT::Quantity, .dimension = D::Time, .default_value = "1ms",
         .source = "assumed: an SG90 moves 0.6 deg in 1 ms", .help = "how often the horn is looked at"},
    };
}

PenLift::PenLift(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    down_angle_deg_ = params.quantity("down_angle") * 180.0 / 3.14159265358979323846;
    const double interval = params.quantity("sample_interval");
    if (!(interval > 0)) throw part_error(this->name(), "sample_interval must be positive");
    sample_cycles_ = std::max<Cycle>(1, clock.cycles_from_seconds(interval));
    require_port<ServoHorn>("horn", true, "the pen servo's horn", [this](ServoHorn& horn) { servo_ = &horn; });
    require_port<Carriage>("x", true, "the X axis' carriage", [this](Carriage& x) { connect_carriage(x_, x); });
    require_port<Carriage>("y", true, "the Y axis' carriage", [this](Carriage& y) { connect_carriage(y_, y); });
    provide_port<ToolContact>("tool", *this, "a motion_oracle's tool");
    sig_down_ = add_signal("down", false, 0);
    sig_x_ = add_signal({"tip_x_mm", true, "mm", "", ""}, 0);
    sig_y_ = add_signal({"tip_y_mm", true, "mm", "", ""}, 0);
}

void PenLift::connect_carriage(Carriage*& slot, Carriage& axis) {
    slot = &axis;
    axis.on_move([this](double) { on_carriage(); });
}

void PenLift::start() { tick(); }

void PenLift::tick() {
    set_down(servo_->angle_deg() >= down_angle_deg_ - 1e-9);
    clock().scheduler().at(clock().cycle() + sample_cycles_, [this](Cycle) { tick(); });
}

void PenLift::set_down(bool down) {
    if (down == down_) return;
    down_ = down;
    publish(sig_down_, down_ ? 1 : 0);
    if (down_) {
        strokes_.emplace_back();
        on_carriage();
    }
}

void PenLift::on_carriage() {
    if (!down_ || x_ == nullptr || y_ == nullptr) return;
    const Point p{x_->position_mm(), y_->position_mm()};
    auto& stroke = strokes_.back();
    if (!stroke.empty() && stroke.back().x_mm == p.x_mm && stroke.back().y_mm == p.y_mm) return;
    stroke.push_back(p);
    publish(sig_x_, p.x_mm);
    publish(sig_y_, p.y_mm);
}

std::string PenLift::summary() {
    std::size_t points = 0;
    for (const auto& s : strokes_) points += s.size();
    char line[160];
    std::snprintf(line, sizeof line, "pen        %s: %s, %zu strokes, %zu points drawn", name().c_str(),
                  down_ ? "down" : "up", strokes_.size(), points);
    return line;
}

}  // namespace avrbench
