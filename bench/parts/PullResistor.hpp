// A resistor from a net to VCC or GND on the board (a pull-up or pull-down),
// or with resistance 0, a tie (a solder bridge or jumper to the rail). One pin,
// "pin"; the net resolves it against the other drivers (wiring/Drive.hpp).
#pragma once

#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class PullResistor final : public Part {
public:
    static std::vector<ParamSpec> param_specs();

    PullResistor(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "pull_resistor"; }
    void start() override;

private:
    std::size_t pin_;
    bool to_vcc_;
    double ohms_;
};

}  // namespace avrbench
