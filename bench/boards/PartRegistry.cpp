#include "boards/PartRegistry.hpp"

#include "parts/Axis.hpp"
#include "parts/Fan.hpp"
#include "parts/Heater.hpp"
#include "parts/LimitSwitch.hpp"
#include "parts/PullResistor.hpp"
#include "parts/RcServo.hpp"
#include "parts/SerialPeer.hpp"
#include "parts/StepDirDriver.hpp"
#include "parts/ThermalPlant.hpp"
#include "parts/Thermistor.hpp"

namespace avrbench {
namespace {

PartType axis(const std::string& kind) {
    PartType t;
    t.name = kind + "_axis";
    t.params = Axis::param_specs();
    t.implied = {{"kind", kind}};
    t.references = {{"driver", {"step_dir_driver"}}};
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params, const PartType::Lookup& lookup) {
        auto& driver = static_cast<StepDirDriver&>(lookup(params.text("driver")));
        return std::make_unique<Axis>(name, clock, params, driver);
    };
    return t;
}

PartType limit_switch() {
    PartType t;
    t.name = "limit_switch";
    t.params = LimitSwitch::param_specs();
    t.references = {{"axis", {"linear_axis"}}};
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params, const PartType::Lookup& lookup) {
        auto& axis_part = static_cast<Axis&>(lookup(params.text("axis")));
        return std::make_unique<LimitSwitch>(name, clock, params, axis_part);
    };
    return t;
}

// Thermal parts (docs/THERMAL.md): a plant, and the heaters, thermistors
// and fans that name it.
PartType thermal_plant() {
    PartType t;
    t.name = "thermal_plant";
    t.params = ThermalPlant::param_specs();
    t.presets = ThermalPlant::presets();
    t.references = {{"filament_driver", {"step_dir_driver"}}};
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params, const PartType::Lookup& lookup) {
        StepDirDriver* driver = nullptr;
        if (params.has("filament_driver") && !params.text("filament_driver").empty()) {
            driver = &static_cast<StepDirDriver&>(lookup(params.text("filament_driver")));
        }
        return std::make_unique<ThermalPlant>(name, clock, params, driver);
    };
    return t;
}

template <class T>
PartType on_plant(const std::string& type_name) {
    PartType t;
    t.name = type_name;
    t.params = T::param_specs();
    if constexpr (requires { T::presets(); }) t.presets = T::presets();
    t.references = {{"plant", {"thermal_plant"}}};
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params, const PartType::Lookup& lookup) {
        auto& plant = static_cast<ThermalPlant&>(lookup(params.text("plant")));
        return std::make_unique<T>(name, clock, params, plant);
    };
    return t;
}

}  // namespace

const std::map<std::string, PartType>& part_types() {
    static const std::map<std::string, PartType> types = [] {
        std::map<std::string, PartType> m;
        for (PartType t : {simple_part_type<StepDirDriver>("step_dir_driver"), axis("linear"), axis("rotary"), limit_switch(), simple_part_type<PullResistor>("pull_resistor"),
                           simple_part_type<SerialPeer>("serial_peer"), simple_part_type<RcServo>("rc_servo"), thermal_plant(),
                           on_plant<Heater>("heater"), on_plant<Thermistor>("thermistor"), on_plant<Fan>("fan")}) {
            m.emplace(t.name, std::move(t));
        }
        for (PartType t : motor_part_types()) m.emplace(t.name, std::move(t));
        return m;
    }();
    return types;
}

}  // namespace avrbench
