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
    virtual void on_move(std::function<void(double position_m)> fn) = 0;
};

}  // namespace avrbench
