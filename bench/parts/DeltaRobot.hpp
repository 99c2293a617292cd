// A rotary delta robot driven by three RC servos (seed 004): ports horn1..3
// require the servos' horns; the arm angle is theta_k = offset_k - horn_k
// (the servo angle at which the upper arm is horizontal, minus the horn's),
// theta > 0 below the base plane. The effector centre follows by forward
// kinematics (parts/DeltaKinematics) and is traced as x_mm, y_mm, z_mm;
// port `effector` provides it to tools (an electromagnet).
#pragma once

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "parts/AcceptedMoves.hpp"
#include "parts/DeltaKinematics.hpp"
#include "parts/Effector.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ServoHorn.hpp"

namespace avrbench {

class DeltaRobot final : public Part, public Effector, public AcceptedMoves {
public:
    // What this part finds (`avrbench findings` lists every kind).
    static const FindingKind kTargetOutOfReach;  // target-out-of-reach
    static std::vector<ParamSpec> param_specs();

    DeltaRobot(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "delta_robot"; }
    void start() override;
    std::string summary() override;
    // The effector moved since the mark: a limit ahead cannot be told.
    void mark_pace() override { pace_effector_mm_ = effector_mm_; }
    bool may_find_more_at_pace(double seconds) override {
        (void)seconds;
        return effector_mm_ != pace_effector_mm_;
    }

    const DeltaGeometry& geometry() const { return geometry_; }
    // The effector centre as of the last sample (mm), and whether the arms' angles reach one.
    const Eigen::Vector3d& effector_mm() const override { return effector_mm_; }
    bool reachable() const { return reachable_; }
    std::array<double, 3> arm_angles_deg() const;
    void on_move(std::function<void(const Eigen::Vector3d&)> fn) override { move_listeners_.push_back(std::move(fn)); }

    // Whether G0/G1 X Y Z lines the firmware accepts are targets in this
    // part's frame (mm, origin at the base centre, z negative below it; the
    // `move_commands` parameter). Bench checks each one with check_accepted_move.
    bool checks_move_commands() const override { return check_moves_; }
    // The firmware answered ok to a move to `target_mm` (`line` quotes it):
    // a target-out-of-reach finding when no pose of the arms reaches it or an
    // arm would need its servo's horn beyond the servo's travel. Targets
    // near either limit are not judged, since a firmware's float32
    // arithmetic may fall either side there: within kReachMarginMm of the
    // reachable space, or within kTravelMarginDeg of the travel's ends (half
    // a degree for a firmware that rounds angles to whole table entries, as
    // seed 004's does, and 0.1 deg for float32).
    bool check_accepted_move(const Eigen::Vector3d& target_mm, const std::string& line) override;
    bool refusal_is_right(const Eigen::Vector3d& target_mm) const override { return reach_problem(target_mm).has_value(); }
    // Why no pose of this robot reaches the target, clearly (beyond the
    // margins below), or nothing when one does: a finding says
    // "<what>; <line> was answered ok<details>".
    struct ReachProblem {
        std::string what, details;
    };
    std::optional<ReachProblem> reach_problem(const Eigen::Vector3d& target_mm) const;
    static constexpr double kReachMarginMm = 0.5;
    static constexpr double kTravelMarginDeg = 0.6;

private:
    void tick();
    void sample();

    DeltaGeometry geometry_;
    std::array<double, 3> offset_deg_{};
    std::array<ServoHorn*, 3> horns_{};
    std::array<std::string, 3> horn_names_;  // the servos', for findings
    Cycle sample_cycles_;
    Eigen::Vector3d effector_mm_ = Eigen::Vector3d::Zero();
    Eigen::Vector3d pace_effector_mm_ = Eigen::Vector3d::Zero();
    bool reachable_ = false;
    bool sampled_ = false;
    bool check_moves_ = true;
    std::size_t sig_x_, sig_y_, sig_z_, sig_reachable_;
    std::vector<std::function<void(const Eigen::Vector3d&)>> move_listeners_;
};

}  // namespace avrbench
