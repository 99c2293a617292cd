#include "boards/PartRegistry.hpp"

#include "parts/Axis.hpp"
#include "parts/LimitSwitch.hpp"
#include "parts/StepDirDriver.hpp"

namespace avrbench {
namespace {

PartType step_dir_driver() {
    PartType t;
    t.name = "step_dir_driver";
    t.params = StepDirDriver::param_specs();
    t.presets = StepDirDriver::presets();
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params, const PartType::Lookup&) {
        return std::make_unique<StepDirDriver>(name, clock, params);
    };
    return t;
}

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

}  // namespace

const std::map<std::string, PartType>& part_types() {
    static const std::map<std::string, PartType> types = [] {
        std::map<std::string, PartType> m;
        for (PartType t : {step_dir_driver(), axis("linear"), axis("rotary"), limit_switch()}) {
            m.emplace(t.name, std::move(t));
        }
        return m;
    }();
    return types;
}

}  // namespace avrbench
