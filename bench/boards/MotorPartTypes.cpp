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
    for (int o : {a, b}) {
        if (o < 1 || o > 4) throw BadInput("part '" + part + "': L293D outputs are 1..4");
    }
    return {a, b};
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
            auto& l293d = static_cast<L293D&>(lookup(params.text("bridge")));
            motor->attach(l293d, {[&l293d, a] { return l293d.winding(a.first, a.second); },
                                  [&l293d, b] { return l293d.winding(b.first, b.second); }});
        } else {
            auto& step_dir = static_cast<StepDirDriver&>(lookup(params.text("driver")));
            motor->attach(step_dir,
                          {[&step_dir] { return step_dir.winding(0); }, [&step_dir] { return step_dir.winding(1); }});
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
        auto& switches = static_cast<LowSideSwitch&>(lookup(params.text("switches")));
        std::vector<std::function<WindingDrive()>> windings;
        for (const int ch : channels) {
            if (ch < 1 || ch > switches.channels()) {
                throw BadInput("part '" + name + "': coil channel " + std::to_string(ch) + " is not a channel of '" +
                               switches.name() + "' (1.." + std::to_string(switches.channels()) + ")");
            }
            HybridStepper* m = motor.get();
            windings.push_back([&switches, ch, m] { return switches.winding(ch, m->supply_v(), m->sense_ohm()); });
        }
        motor->attach(switches, std::move(windings));
        return motor;
    };
    return t;
}

}  // namespace

std::vector<PartType> motor_part_types() {
    return {simple_part_type<L293D>("l293d"), simple_part_type<LowSideSwitch>("low_side_switch"),
            simple_part_type<ShiftRegister595>("shift_register_595"), hybrid_stepper(), unipolar_stepper()};
}

}  // namespace avrbench
