// The kinematics of a rotary delta robot (three arms on a base triangle,
// parallelogram forearms to an effector triangle), in the convention of seed
// 004 §2 (the Trossen-forum solution the thesis uses): origin at the base
// triangle's centre in the plane of the servo axes, z negative below it, arm
// 1 in the YZ plane at F1 = (0, -f/(2 sqrt 3), 0), arms 2 and 3 rotated by
// +-120 degrees about z; an arm angle theta > 0 points the upper arm below
// the base plane.
#pragma once

#include <array>
#include <optional>

#include <Eigen/Dense>

namespace avrbench {

struct DeltaGeometry {
    double base_side_mm = 233.2;      // f
    double effector_side_mm = 80.0;   // e
    double upper_arm_mm = 60.0;       // r_f
    double forearm_mm = 350.0;        // r_e
};

// The effector centre for three arm angles (degrees), or nothing when the
// three forearm spheres do not meet.
std::optional<Eigen::Vector3d> delta_forward(const DeltaGeometry& g, const std::array<double, 3>& theta_deg);

// The arm angles (degrees) for an effector centre, or nothing when the point
// is out of reach of some arm (the outer solution of each arm's circle and
// sphere, as the thesis picks it).
std::optional<std::array<double, 3>> delta_inverse(const DeltaGeometry& g, const Eigen::Vector3d& p_mm);

}  // namespace avrbench
