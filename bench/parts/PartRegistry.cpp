#include "parts/PartRegistry.hpp"

#include <stdexcept>

namespace avrbench {
namespace {

// Function-local: registrations run during static initialisation, in any
// order of translation units.
std::map<std::string, PartType>& registry() {
    static std::map<std::string, PartType> types;
    return types;
}

}  // namespace

bool register_part_type(PartType type) {
    const std::string name = type.name;
    // Every part's: how finely its real-valued signals are recorded (Part::set_trace_resolution).
    type.params.push_back({.name = "trace_resolution", .type = ParamType::Quantity, .default_value = "0",
                           .source = "none: every value, as the part computes it",
                           .help = "record a real-valued signal of the part (a temperature, position, voltage) only when it has "
                                   "changed by at least this much since the last value recorded, in the signal's own unit "
                                   "(0: every value)",
                           .min = 0, .max = 1e6});
    type.build = [build = std::move(type.build)](const std::string& part, Mcu& clock, const ParamValues& params) {
        std::unique_ptr<Part> made = build(part, clock, params);
        made->set_trace_resolution(params.quantity("trace_resolution"));
        return made;
    };
    if (!registry().emplace(name, std::move(type)).second) {
        throw std::logic_error("part type '" + name + "' registered twice");
    }
    return true;
}

const std::map<std::string, PartType>& part_types() { return registry(); }

}  // namespace avrbench
