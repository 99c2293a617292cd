#include "boards/YamlKeys.hpp"

#include <set>

#include "core/Errors.hpp"

namespace avrbench {

void check_unique_keys(const YAML::Node& node, const std::string& path) {
    if (node.IsSequence()) {
        for (const auto& item : node) check_unique_keys(item, path);
        return;
    }
    if (!node.IsMap()) return;
    std::set<std::string> seen;
    for (const auto& kv : node) {
        const std::string where = path + ":" + std::to_string(kv.first.Mark().line + 1);
        if (!kv.first.IsScalar()) throw BadInput(where + ": a key must be a single value");
        if (!seen.insert(kv.first.Scalar()).second) throw BadInput(where + ": duplicate key '" + kv.first.Scalar() + "'");
        check_unique_keys(kv.second, path);
    }
}

}  // namespace avrbench
