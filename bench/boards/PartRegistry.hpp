// The part types a board file may name: for each, its parameters, presets
// and how to build it. A part's pins and ports are its own (Part); the
// board's nets connect them.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

struct PartType {
    std::string name;
    std::vector<ParamSpec> params;
    // Preset tables selected by the "preset" parameter, if the type has one.
    std::map<std::string, std::map<std::string, std::string>> presets;
    // Fixed values this type name implies (linear_axis -> kind: linear).
    std::map<std::string, std::string> implied;
    std::function<std::unique_ptr<Part>(const std::string& name, Mcu& clock, const ParamValues& params)> build;
};

// A part type built from its parameters, with the part's presets if it has any.
template <class T>
PartType simple_part_type(const std::string& type_name) {
    PartType t;
    t.name = type_name;
    t.params = T::param_specs();
    if constexpr (requires { T::presets(); }) t.presets = T::presets();
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params) {
        return std::make_unique<T>(name, clock, params);
    };
    return t;
}

// Every part type the bench ships, by name.
const std::map<std::string, PartType>& part_types();

// The motor layer's types (bridges, switches, 74HC595, steppers), in boards/MotorPartTypes.cpp.
std::vector<PartType> motor_part_types();

}  // namespace avrbench
