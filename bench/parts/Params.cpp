#include "parts/Params.hpp"

#include "core/Units.hpp"

#include <cmath>

#include "core/Errors.hpp"

namespace avrbench {
namespace {

void parse_into(const ParamSpec& spec, const std::string& value, const std::string& what, ParamValues& out) {
    switch (spec.type) {
        case ParamType::Quantity:
            out.set_quantity(spec.name, parse_quantity(value, spec.dimension, what));
            return;
        case ParamType::Integer: {
            const double v = parse_quantity(value, Dimension::Dimensionless, what);
            if (std::floor(v) != v) throw BadInput(what + ": '" + value + "' is not a whole number");
            out.set_quantity(spec.name, v);
            return;
        }
        case ParamType::Choice: {
            for (const auto& c : spec.choices) {
                if (c == value) {
                    out.set_text(spec.name, value);
                    return;
                }
            }
            std::string list;
            for (const auto& c : spec.choices) list += (list.empty() ? "" : ", ") + c;
            throw BadInput(what + ": '" + value + "' is not one of " + list);
        }
        case ParamType::Text:
            out.set_text(spec.name, value);
            return;
    }
}

}  // namespace

double ParamValues::quantity(const std::string& name) const {
    auto it = quantities_.find(name);
    if (it == quantities_.end()) throw BadInput("parameter '" + name + "' has no value");
    return it->second;
}

long long ParamValues::integer(const std::string& name) const {
    // Whole numbers only, within +-2^53 (exact in a double): never a bare cast.
    constexpr std::int64_t kLimit = std::int64_t{1} << 53;
    return checked_integer(quantity(name), "parameter '" + name + "'", -kLimit, kLimit);
}

const std::string& ParamValues::text(const std::string& name) const {
    auto it = texts_.find(name);
    if (it == texts_.end()) throw BadInput("parameter '" + name + "' has no value");
    return it->second;
}

bool ParamValues::has(const std::string& name) const {
    return quantities_.count(name) != 0 || texts_.count(name) != 0;
}

ParamValues resolve_params(const std::vector<ParamSpec>& specs, const std::map<std::string, std::string>& preset,
                           const std::vector<RawParam>& given, const std::string& part_name,
                           const std::string& part_location) {
    ParamValues values;
    auto find_spec = [&](const std::string& name) -> const ParamSpec* {
        for (const auto& s : specs) {
            if (s.name == name) return &s;
        }
        return nullptr;
    };
    for (const auto& spec : specs) {
        auto p = preset.find(spec.name);
        const std::string& text = p != preset.end() ? p->second : spec.default_value;
        if (!text.empty()) {
            parse_into(spec, text, part_location + ": part '" + part_name + "': default " + spec.name, values);
        }
    }
    for (const auto& raw : given) {
        const ParamSpec* spec = find_spec(raw.name);
        if (spec == nullptr) {
            std::string known;
            for (const auto& s : specs) known += (known.empty() ? "" : ", ") + s.name;
            throw BadInput(raw.location + ": part '" + part_name + "': unknown parameter '" + raw.name +
                           "' (known: " + known + ")");
        }
        parse_into(*spec, raw.value, raw.location + ": part '" + part_name + "': " + raw.name, values);
    }
    for (const auto& spec : specs) {
        if (spec.required && !values.has(spec.name)) {
            throw BadInput(part_location + ": part '" + part_name + "': missing required parameter '" + spec.name +
                           "'" + (spec.help.empty() ? "" : " (" + spec.help + ")"));
        }
    }
    return values;
}

}  // namespace avrbench
