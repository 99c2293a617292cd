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
    if (!registry().emplace(name, std::move(type)).second) {
        throw std::logic_error("part type '" + name + "' registered twice");
    }
    return true;
}

const std::map<std::string, PartType>& part_types() { return registry(); }

}  // namespace avrbench
