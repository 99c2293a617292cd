// What a tool on a carriage offers the parts that judge its work: whether it
// touches the work now (a plotter's pen on the paper). The motion oracle
// (parts/MotionOracle) reads it to tell drawing from travelling.
#pragma once

#include "parts/PortType.hpp"

namespace avrbench {

class ToolContact {
public:
    static constexpr PortType kPort{"tool", "a pen_lift's pen"};
    virtual ~ToolContact() = default;
    virtual bool tool_down() const = 0;
};

}  // namespace avrbench
