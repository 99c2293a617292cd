// Part types of the motor layer (docs/MOTOR.md): bridges, switches, the
// 74HC595 and the stepper motors they drive. Registered by PartRegistry.cpp.
#include <sstream>

#include "boards/PartRegistry.hpp"
#include "core/Errors.hpp"
#include "parts/HybridStepper.hpp"
#include "parts/L293D.hpp"
#include "parts/LowSideSwitch.hpp"
#include "parts/ShiftRegister595.hpp"
#include "parts/StepDirDriver.hpp"

namespace avrbench {
namespace {

// "1,2" -> {1, 2}
std::pair<int, int> output_pair(const std::string& text, const std::string& part, const std::string& param) {
    std::istringstream in(text);
    int a = 0, b = 0;
    char comma = 0;
    if (!(in >> a >> comma >> b) || comma != ',' || !(in >> std::ws).eof()) {
        throw BadInput("part '" + part + "': " + param + " '" + text + "' is not two outputs 'plus,minus' (e.g. 1,2)");
    }
    return {a, b};
}

template <class T>
PartType simple(const std::string& type_name) {
    PartType t;
    t.name = type_name;
    t.params = T::param_specs();
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params, const PartType::Lookup&) {
        return std::make_unique<T>(name, clock, params);
    };
    return t;
}

PartType hybrid_stepper() {
    PartType t;
    t.name = "hybrid_stepper";
    t.params = HybridStepper::param_specs(false);
    t.presets = HybridStepper::presets();
    t.references = {{"bridge", {"l293d"}}, {"driver", {"step_dir_driver"}}};
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params, const PartType::Lookup& lookup) {
        const bool bridge = params.has("bridge") && !params.text("bridge").empty();
        const bool driver = params.has("driver") && !params.text("driver").empty();
        if (bridge == driver) {
            throw BadInput("part '" + name + "': give either bridge (an l293d) or driver (a step_dir_driver)");
        }
        auto motor = std::make_unique<HybridStepper>(name, clock, params, false);
        if (bridge) {
            const auto a = output_pair(params.text("phase_a"), name, "phase_a");
            const auto b = output_pair(params.text("phase_b"), name, "phase_b");
            motor->attach_bridge(static_cast<L293D&>(lookup(params.text("bridge"))), a.first, a.second, b.first,
                                 b.second);
        } else {
            motor->attach_driver(static_cast<StepDirDriver&>(lookup(params.text("driver"))));
        }
        return motor;
    };
    return t;
}

PartType unipolar_stepper() {
    PartType t;
    t.name = "unipolar_stepper";
    t.params = HybridStepper::param_specs(true);
    t.presets = HybridStepper::presets();
    t.references = {{"switches", {"low_side_switch"}}};
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params, const PartType::Lookup& lookup) {
        auto motor = std::make_unique<HybridStepper>(name, clock, params, true);
        const std::array<int, 4> channels = {
            static_cast<int>(params.integer("coil_a")), static_cast<int>(params.integer("coil_b")),
            static_cast<int>(params.integer("coil_c")), static_cast<int>(params.integer("coil_d"))};
        motor->attach_switches(static_cast<LowSideSwitch&>(lookup(params.text("switches"))), channels);
        return motor;
    };
    return t;
}

}  // namespace

std::vector<PartType> motor_part_types() {
    return {simple<L293D>("l293d"), simple<LowSideSwitch>("low_side_switch"),
            simple<ShiftRegister595>("shift_register_595"), hybrid_stepper(), unipolar_stepper()};
}

}  // namespace avrbench
