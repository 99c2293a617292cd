// What a mechanism offers the tool on its end: the tool point in space (mm,
// the mechanism's frame) and a call whenever it moves.
#pragma once

#include <functional>

#include <Eigen/Dense>

#include "parts/PortType.hpp"

namespace avrbench {

class Effector {
public:
    static constexpr PortType kPort{"effector", "a delta_robot's effector"};
    virtual ~Effector() = default;
    virtual const Eigen::Vector3d& effector_mm() const = 0;
    virtual void on_move(std::function<void(const Eigen::Vector3d&)> fn) = 0;
};

}  // namespace avrbench
