#include "parts/DeltaRobot.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
#include <cstdio>

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(DeltaRobot, "delta_robot");

const FindingKind DeltaRobot::kTargetOutOfReach = FindingKind::declare("target-out-of-reach", "the firmware answered ok to a move the machine cannot make (a delta's arms or servos)", Severity::Warning);
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

}  // namespace

std::vector<ParamSpec> DeltaRobot::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    const char* geometry = "seed 004 §1: CreateDelta(233.2, 80, 60, 350)";
    return {
        {.name = "base_side", .type = PT::Quantity, .dimension = D::Length, .default_value = "233.2mm", .source = geometry,
         .help = "f: side of the base triangle through the servo axes"},
        {.name = "effector_side", .type = PT::Quantity, .dimension = D::Length, .default_value = "80mm", .source = geometry,
         .help = "e: side of the effector triangle through the forearm joints"},
        {.name = "upper_arm", .type = PT::Quantity, .dimension = D::Length, .default_value = "60mm", .source = geometry,
         .help = "r_f: servo axis to elbow"},
        {.name = "forearm", .type = PT::Quantity, .dimension = D::Length, .default_value = "350mm", .source = geometry,
         .help = "r_e: elbow to effector joint (the parallelogram)"},
        {.name = "offset1", .type = PT::Quantity, .dimension = D::Angle, .default_value = "90deg",
         .source = "assumed; seed 004's firmware: 111 deg", .help = "servo 1's angle with its upper arm horizontal"},
        {.name = "offset2", .type = PT::Quantity, .dimension = D::Angle, .default_value = "90deg",
         .source = "assumed; seed 004's firmware: 110 deg", .help = "servo 2's angle with its upper arm horizontal"},
        {.name = "offset3", .type = PT::Quantity, .dimension = D::Angle, .default_value = "90deg",
         .source = "assumed; seed 004's firmware: 116 deg", .help = "servo 3's angle with its upper arm horizontal"},
        {.name = "move_commands", .type = PT::Choice, .default_value = "base_frame", .choices = {"base_frame", "unchecked"},
         .source = "firmware/delta's G1 X Y Z",
         .help = "base_frame: G0/G1 X Y Z (mm) answered ok are targets in this part's frame and are checked "
                 "(target-out-of-reach); unchecked: the firmware uses another frame"},
        {.name = "sample_interval", .type = PT::Quantity, .dimension = D::Time, .default_value = "5ms",
         .source = "assumed: a 285 deg/s servo moves 1.4 deg in 5 ms",
         .help = "how often the effector position is recomputed from the horns"},
    };
}

DeltaRobot::DeltaRobot(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    geometry_.base_side_mm = params.quantity("base_side") * 1e3;
    geometry_.effector_side_mm = params.quantity("effector_side") * 1e3;
    geometry_.upper_arm_mm = params.quantity("upper_arm") * 1e3;
    geometry_.forearm_mm = params.quantity("forearm") * 1e3;
    if (!(geometry_.base_side_mm > geometry_.effector_side_mm) || !(geometry_.upper_arm_mm > 0) ||
        !(geometry_.forearm_mm > geometry_.upper_arm_mm)) {
        throw part_error(this->name(), "needs base_side > effector_side and forearm > upper_arm > 0");
    }
    for (int k = 0; k < 3; ++k) offset_deg_[static_cast<std::size_t>(k)] = params.quantity("offset" + std::to_string(k + 1)) * kRadToDeg;
    check_moves_ = params.text("move_commands") == "base_frame";
    const double interval = params.quantity("sample_interval");
    if (!(interval > 0)) throw part_error(this->name(), "sample_interval must be positive");
    sample_cycles_ = std::max<Cycle>(1, clock.cycles_from_seconds(interval));
    for (int k = 0; k < 3; ++k) {
        const auto arm = static_cast<std::size_t>(k);
        require_port<ServoHorn>("horn" + std::to_string(k + 1), true, "an rc_servo's horn",
                                [this, arm](ServoHorn& horn, Part& servo) {
                                    horns_[arm] = &horn;
                                    horn_names_[arm] = servo.name();
                                });
    }
    provide_port<Effector>("effector", *this, "the effector centre, for a tool such as an electromagnet");
    sig_x_ = add_signal({"x_mm", true, "mm", "position", ""}, 0);
    sig_y_ = add_signal({"y_mm", true, "mm", "position", ""}, 0);
    sig_z_ = add_signal({"z_mm", true, "mm", "position", ""}, 0);
    sig_reachable_ = add_signal("reachable", false, 0);
}


void DeltaRobot::start() { tick(); }

void DeltaRobot::tick() {
    sample();
    clock().scheduler().at(clock().cycle() + sample_cycles_, [this](Cycle) { tick(); });
}

std::array<double, 3> DeltaRobot::arm_angles_deg() const {
    std::array<double, 3> theta{};
    for (std::size_t k = 0; k < 3; ++k) theta[k] = offset_deg_[k] - horns_[k]->angle_deg();
    return theta;
}

void DeltaRobot::sample() {
    const auto p = delta_forward(geometry_, arm_angles_deg());
    const bool moved = p.has_value() != reachable_ || (p && (!sampled_ || (*p - effector_mm_).norm() > 1e-9));
    if (!moved) return;
    sampled_ = true;
    reachable_ = p.has_value();
    publish(sig_reachable_, reachable_ ? 1 : 0);
    if (!p) return;
    effector_mm_ = *p;
    publish(sig_x_, p->x());
    publish(sig_y_, p->y());
    publish(sig_z_, p->z());
    for (auto& fn : move_listeners_) fn(effector_mm_);
}

std::optional<DeltaRobot::ReachProblem> DeltaRobot::reach_problem(const Eigen::Vector3d& target_mm) const {
    char where[96];
    std::snprintf(where, sizeof where, "(%.3f, %.3f, %.3f) mm", target_mm.x(), target_mm.y(), target_mm.z());
    // The robot hangs below its base (seed 004 §2: z < 0): above the base
    // plane the forearms would pass through it, and the forward kinematics
    // (the lower meeting point of the three spheres) never goes there.
    const auto pose = [this](const Eigen::Vector3d& p) {
        return p.z() < 0 ? delta_inverse(geometry_, p) : std::nullopt;
    };
    const auto theta = pose(target_mm);
    if (!theta) {
        // Out of reach, and clearly so: every point within the margin is too.
        for (int axis = 0; axis < 3; ++axis) {
            for (double sign : {-1.0, 1.0}) {
                Eigen::Vector3d near = target_mm;
                near[axis] += sign * kReachMarginMm;
                if (pose(near)) return std::nullopt;
            }
        }
        return ReachProblem{"no pose of the arms below the base reaches the target", std::string(", target ") + where};
    }
    for (std::size_t k = 0; k < 3; ++k) {
        const double horn = offset_deg_[k] - (*theta)[k];
        const double lo = horns_[k]->min_angle_deg(), hi = horns_[k]->max_angle_deg();
        if (horn >= lo - kTravelMarginDeg && horn <= hi + kTravelMarginDeg) continue;
        char detail[200];
        std::snprintf(detail, sizeof detail, ", target %s needs %s at %.1f deg, its travel %g..%g deg", where,
                      horn_names_[k].c_str(), horn, lo, hi);
        return ReachProblem{"arm " + std::to_string(k + 1) + " beyond its servo's travel", detail};
    }
    return std::nullopt;
}

bool DeltaRobot::check_accepted_move(const Eigen::Vector3d& target_mm, const std::string& line) {
    const auto why = reach_problem(target_mm);
    if (!why) return true;
    report(DeltaRobot::kTargetOutOfReach, why->what + "; " + line + " was answered ok" + why->details);
    return false;
}

std::string DeltaRobot::summary() {
    char line[200];
    std::snprintf(line, sizeof line, "delta      %s: effector at (%.2f, %.2f, %.2f) mm%s", name().c_str(), effector_mm_.x(),
                  effector_mm_.y(), effector_mm_.z(), reachable_ ? "" : ", arms in no reachable pose");
    return line;
}

}  // namespace avrbench
