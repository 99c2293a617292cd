#include "parts/DeltaKinematics.hpp"

#include <cmath>
#include <numbers>

namespace avrbench {
namespace {


// A point rotated about z by `deg`.
Eigen::Vector3d rotated_z(const Eigen::Vector3d& p, double deg) {
    return Eigen::AngleAxisd(deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()) * p;
}

}  // namespace

std::optional<Eigen::Vector3d> delta_forward(const DeltaGeometry& g, const std::array<double, 3>& theta_deg) {
    // Each forearm's far end sits on a sphere of radius r_e about its elbow,
    // moved inwards by the effector's own offset e/(2 sqrt 3): the effector
    // centre lies on all three spheres (seed 004 §2, "J_i'").
    const double inset = (g.base_side_mm - g.effector_side_mm) / (2.0 * std::sqrt(3.0));
    std::array<Eigen::Vector3d, 3> centre;
    for (int i = 0; i < 3; ++i) {
        const double t = theta_deg[static_cast<std::size_t>(i)] * std::numbers::pi / 180.0;
        const Eigen::Vector3d arm1(0.0, -(inset + g.upper_arm_mm * std::cos(t)), -g.upper_arm_mm * std::sin(t));
        centre[static_cast<std::size_t>(i)] = rotated_z(arm1, 120.0 * i);
    }
    // Three spheres of equal radius: the difference of two sphere equations
    // is a plane; two planes meet in a line p = p0 + s u; the line meets a sphere.
    const Eigen::Vector3d& c1 = centre[0];
    const Eigen::Vector3d n2 = centre[1] - c1, n3 = centre[2] - c1;
    const double k2 = 0.5 * (centre[1].squaredNorm() - c1.squaredNorm());
    const double k3 = 0.5 * (centre[2].squaredNorm() - c1.squaredNorm());
    const Eigen::Vector3d u = n2.cross(n3);
    if (u.squaredNorm() < 1e-12) return std::nullopt;
    // p0: on both planes (n2.p = k2, n3.p = k3) and in the plane through the origin normal to u.
    Eigen::Matrix3d m;
    m.row(0) = n2.transpose();
    m.row(1) = n3.transpose();
    m.row(2) = u.transpose();
    const Eigen::Vector3d p0 = m.colPivHouseholderQr().solve(Eigen::Vector3d(k2, k3, 0.0));
    // |p0 + s u - c1|^2 = r_e^2
    const Eigen::Vector3d d = p0 - c1;
    const double a = u.squaredNorm(), b = 2.0 * u.dot(d), c = d.squaredNorm() - g.forearm_mm * g.forearm_mm;
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0) return std::nullopt;
    const double s1 = (-b + std::sqrt(disc)) / (2.0 * a), s2 = (-b - std::sqrt(disc)) / (2.0 * a);
    const Eigen::Vector3d q1 = p0 + s1 * u, q2 = p0 + s2 * u;
    return q1.z() < q2.z() ? q1 : q2;  // the effector hangs below the base
}

std::optional<std::array<double, 3>> delta_inverse(const DeltaGeometry& g, const Eigen::Vector3d& p_mm) {
    std::array<double, 3> theta{};
    for (int i = 0; i < 3; ++i) {
        // In arm i's frame (rotate the point by -120 i), the arm swings in the YZ plane.
        const Eigen::Vector3d p = rotated_z(p_mm, -120.0 * i);
        const double y_f = -g.base_side_mm / (2.0 * std::sqrt(3.0));
        // The forearm's end, moved to the effector's edge: (x, y - e/(2 sqrt 3), z).
        const double y0 = p.y() - g.effector_side_mm / (2.0 * std::sqrt(3.0));
        const double x0 = p.x(), z0 = p.z();
        // Elbow J = (0, yj, zj): |J - F|^2 = r_f^2 and |J - E|^2 = r_e^2, i.e.
        // the circle of radius sqrt(r_e^2 - x0^2) about (y0, z0) in the YZ plane.
        const double r2 = g.forearm_mm * g.forearm_mm - x0 * x0;
        if (r2 <= 0 || z0 == 0) return std::nullopt;
        // Subtracting the two circle equations: zj = a + b yj.
        const double a = (y0 * y0 + z0 * z0 - r2 - y_f * y_f + g.upper_arm_mm * g.upper_arm_mm) / (2.0 * z0);
        const double b = (y_f - y0) / z0;
        const double disc = -(a + b * y_f) * (a + b * y_f) + g.upper_arm_mm * g.upper_arm_mm * (b * b + 1.0);
        if (disc < 0) return std::nullopt;
        const double yj = (y_f - a * b - std::sqrt(disc)) / (b * b + 1.0);  // the outer elbow
        const double zj = a + b * yj;
        theta[static_cast<std::size_t>(i)] = std::atan2(-zj, y_f - yj) * 180.0 / std::numbers::pi;
    }
    return theta;
}

}  // namespace avrbench
