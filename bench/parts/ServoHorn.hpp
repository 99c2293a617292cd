// What an RC servo offers a mechanism fixed to its output shaft: the horn's
// angle now and its travel, in degrees of the servo's calibration.
#pragma once

#include "parts/PortType.hpp"

namespace avrbench {

class ServoHorn {
public:
    static constexpr PortType kPort{"horn", "an rc_servo's horn"};
    virtual ~ServoHorn() = default;
    virtual double angle_deg() const = 0;
    virtual double min_angle_deg() const = 0;
    virtual double max_angle_deg() const = 0;
};

}  // namespace avrbench
