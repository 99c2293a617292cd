// The part types a board file may name: for each, its parameters, presets
// and how to build it. A part's pins and ports are its own (Part); the
// board's nets connect them.
//
// Each part registers itself in its own source file, next to its code
// (REGISTER_PART(StepDirDriver, "step_dir_driver");), so a new part is its two
// files and nothing else: no list of types lives anywhere. The parts library
// is linked whole (bench/CMakeLists.txt), so a registration is never dropped
// by the linker for want of a reference.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "parts/HostConnector.hpp"
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
    // Its parts are serial ports a host attaches to (parts/HostConnector.hpp):
    // a board file that has one can take a G-code job.
    bool host_connector = false;
    // Its ports only watch other parts (a motion oracle reading carriages on
    // several MCUs' boards): it joins no clock group, and takes the board's
    // first MCU's clock. A type says so with `static constexpr bool kObserver = true;`.
    bool observer = false;
};

// A part type built from its parameters, with the part's presets if it has any.
template <class T>
PartType simple_part_type(const std::string& type_name) {
    PartType t;
    t.name = type_name;
    t.params = T::param_specs();
    if constexpr (requires { T::presets(); }) t.presets = T::presets();
    t.host_connector = std::is_base_of_v<HostConnector, T>;
    if constexpr (requires { T::kObserver; }) t.observer = T::kObserver;
    t.build = [](const std::string& name, Mcu& clock, const ParamValues& params) {
        return std::make_unique<T>(name, clock, params);
    };
    return t;
}

// Adds a type (during static initialisation; see REGISTER_PART). A name
// registered twice is a programming error: std::logic_error.
bool register_part_type(PartType type);

// Every registered part type, by name.
const std::map<std::string, PartType>& part_types();

#define AVRBENCH_CONCAT_INNER(a, b) a##b
#define AVRBENCH_CONCAT(a, b) AVRBENCH_CONCAT_INNER(a, b)
// At namespace scope in a part's .cpp: the board-file type `name` builds T
// from its parameters (T::param_specs(), T::presets() if it has them).
#define REGISTER_PART(T, name) \
    [[maybe_unused]] static const bool AVRBENCH_CONCAT(registered_part_, __COUNTER__) = \
        ::avrbench::register_part_type(::avrbench::simple_part_type<T>(name))
// The same for a type built some other way (a PartType expression).
#define REGISTER_PART_TYPE(part_type) \
    [[maybe_unused]] static const bool AVRBENCH_CONCAT(registered_part_, __COUNTER__) = \
        ::avrbench::register_part_type(part_type)

}  // namespace avrbench
