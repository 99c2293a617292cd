#include "parts/Params.hpp"

#include "core/Time.hpp"
#include "core/Units.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/Errors.hpp"

namespace avrbench {
namespace {

// " s", " m", ... after a range in SI units; "" for bare numbers.
std::string si_unit_suffix(Dimension d) {
    switch (d) {
        case Dimension::Dimensionless: return "";
        case Dimension::Time: return " s";
        case Dimension::Length: return " m";
        case Dimension::Frequency: return " Hz";
        case Dimension::Angle: return " rad";
        case Dimension::Voltage: return " V";
        case Dimension::Current: return " A";
        case Dimension::Resistance: return " ohm";
        case Dimension::Power: return " W";
        case Dimension::Temperature: return " degC";
        case Dimension::ThermalResistance: return " K/W";
        case Dimension::HeatCapacity: return " J/K";
        case Dimension::ThermalConductance: return " W/K";
        case Dimension::Torque: return " N*m";
        case Dimension::Inductance: return " H";
        case Dimension::Inertia: return " kg*m^2";
        case Dimension::Speed: return " m/s";
        case Dimension::Acceleration: return " m/s^2";
        case Dimension::TorqueConstant: return " N*m/A";
        case Dimension::RotaryDamping: return " N*m*s/rad";
    }
    return "";
}

std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

void check_range(const ParamSpec& spec, double v, const std::string& value, const std::string& what) {
    const ParamRange r = range_of(spec);
    if (v >= r.min && v <= r.max) return;
    throw BadInput(what + ": '" + value + "' is outside " + number_text(r.min) + " .. " + number_text(r.max) +
                   si_unit_suffix(spec.dimension));
}

void parse_into(const ParamSpec& spec, const std::string& value, const std::string& what, ParamValues& out) {
    switch (spec.type) {
        case ParamType::Quantity: {
            const double v = parse_quantity(value, spec.dimension, what);
            check_range(spec, v, value, what);
            out.set_quantity(spec.name, v);
            return;
        }
        case ParamType::Integer: {
            const double v = parse_quantity(value, Dimension::Dimensionless, what);
            if (std::floor(v) != v) throw BadInput(what + ": '" + value + "' is not a whole number");
            check_range(spec, v, value, what);
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
        case ParamType::Path:
            out.set_text(spec.name, value);
            return;
    }
}

}  // namespace

ParamRange dimension_range(Dimension dimension) {
    switch (dimension) {
        case Dimension::Dimensionless: return {-1e15, 1e15};  // counts and ratios; parts narrow them
        case Dimension::Time: return {0, kMaxRunSeconds};     // no run is longer (core/Time.hpp)
        case Dimension::Length: return {0, 1000};             // m: carriages, travels, filament
        case Dimension::Frequency: return {0, 1e9};           // Hz: no AVR signal is faster
        case Dimension::Angle: return {-1000, 1000};          // rad
        case Dimension::Voltage: return {0, 1000};            // V: supplies and references
        case Dimension::Current: return {0, 1000};            // A
        case Dimension::Resistance: return {0, 1e12};         // ohm: 0 = a short or tie
        case Dimension::Power: return {0, 1e6};               // W
        case Dimension::Temperature: return {-273.15, 5000};  // degC: above absolute zero
        case Dimension::ThermalResistance: return {0, 1e6};   // K/W
        case Dimension::HeatCapacity: return {0, 1e7};        // J/K
        case Dimension::ThermalConductance: return {0, 1e6};  // W/K
        case Dimension::Torque: return {0, 1e4};              // N*m
        case Dimension::Inductance: return {0, 100};          // H
        case Dimension::Inertia: return {0, 1e3};             // kg*m^2
        case Dimension::Speed: return {0, 1e3};               // m/s
        case Dimension::Acceleration: return {0, 1e6};        // m/s^2
        case Dimension::TorqueConstant: return {0, 1e3};      // N*m/A
        case Dimension::RotaryDamping: return {0, 1e3};       // N*m*s/rad
    }
    return {-1e15, 1e15};
}

ParamRange range_of(const ParamSpec& spec) {
    const ParamRange d = dimension_range(spec.dimension);
    return {std::isnan(spec.min) ? d.min : spec.min, std::isnan(spec.max) ? d.max : spec.max};
}

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
        std::string value = raw.value;
        if (spec->type == ParamType::Path && !raw.directory.empty() && std::filesystem::path(value).is_relative()) {
            value = (std::filesystem::path(raw.directory) / value).string();
        }
        parse_into(*spec, value, raw.location + ": part '" + part_name + "': " + raw.name, values);
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
