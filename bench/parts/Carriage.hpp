// What a linear axis offers the parts that watch its carriage (limit
// switches, a pen's tip, a hall-effect endstop): where it is, how far it can
// go, and a call whenever it moves.
#pragma once

#include <functional>

#include "parts/PortType.hpp"

namespace avrbench {

class Carriage {
public:
    static constexpr PortType kPort{"carriage", "a linear axis' carriage"};
    virtual ~Carriage() = default;
    virtual double position_mm() const = 0;  // 0 .. travel_mm()
    virtual double travel_mm() const = 0;
    // How far one STEP pulse moves it: the finest position the axis can
    // reach, so the tolerance of "it got there" (parts/MotionOracle).
    virtual double step_mm() const = 0;
    virtual void on_move(std::function<void(double position_m)> fn) = 0;
};

}  // namespace avrbench
