// Part types of the motor layer (docs/MOTOR.md): bridges, switches, the
// 74HC595 and the stepper motors they drive. Registered by PartRegistry.cpp.
#include "boards/PartRegistry.hpp"
#include "parts/HybridStepper.hpp"
#include "parts/L293D.hpp"
#include "parts/LowSideSwitch.hpp"
#include "parts/ShiftRegister595.hpp"

namespace avrbench {
namespace {

PartType stepper(const std::string& type_name, bool unipolar) {
    PartType t;
    t.name = type_name;
    t.params = HybridStepper::param_specs(unipolar);
    t.presets = HybridStepper::presets();
    t.build = [unipolar](const std::string& name, Mcu& clock, const ParamValues& params) {
        return std::make_unique<HybridStepper>(name, clock, params, unipolar);
    };
    return t;
}

}  // namespace

std::vector<PartType> motor_part_types() {
    return {simple_part_type<L293D>("l293d"), simple_part_type<LowSideSwitch>("low_side_switch"),
            simple_part_type<ShiftRegister595>("shift_register_595"), stepper("hybrid_stepper", false),
            stepper("unipolar_stepper", true)};
}

}  // namespace avrbench
