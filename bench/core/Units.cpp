#include "core/Units.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "core/Errors.hpp"
#include "core/Time.hpp"

namespace avrbench {
namespace {

struct UnitEntry {
    const char* symbol;
    Dimension dimension;
    double to_si;
};

// Every unit the bench accepts, with its factor to SI.
constexpr UnitEntry kUnits[] = {
    {"s", Dimension::Time, 1.0},           {"ms", Dimension::Time, 1e-3},
    {"us", Dimension::Time, 1e-6},         {"ns", Dimension::Time, 1e-9},
    {"min", Dimension::Time, 60.0},        {"h", Dimension::Time, 3600.0},
    {"m", Dimension::Length, 1.0},         {"mm", Dimension::Length, 1e-3},
    {"um", Dimension::Length, 1e-6},       {"cm", Dimension::Length, 1e-2},
    {"Hz", Dimension::Frequency, 1.0},     {"kHz", Dimension::Frequency, 1e3},
    {"MHz", Dimension::Frequency, 1e6},    {"rpm", Dimension::Frequency, 1.0 / 60.0},
    {"rad", Dimension::Angle, 1.0},        {"deg", Dimension::Angle, 3.14159265358979323846 / 180.0},
    {"rev", Dimension::Angle, 2.0 * 3.14159265358979323846},
    {"V", Dimension::Voltage, 1.0},        {"mV", Dimension::Voltage, 1e-3},
    {"A", Dimension::Current, 1.0},        {"mA", Dimension::Current, 1e-3},
    {"ohm", Dimension::Resistance, 1.0},   {"kohm", Dimension::Resistance, 1e3},
    {"Mohm", Dimension::Resistance, 1e6},
    {"W", Dimension::Power, 1.0},          {"mW", Dimension::Power, 1e-3},
    {"degC", Dimension::Temperature, 1.0},
    {"K/W", Dimension::ThermalResistance, 1.0},
    {"J/K", Dimension::HeatCapacity, 1.0},
    {"W/K", Dimension::ThermalConductance, 1.0}, {"mW/K", Dimension::ThermalConductance, 1e-3},
    {"N*m", Dimension::Torque, 1.0},       {"mN*m", Dimension::Torque, 1e-3},
    {"H", Dimension::Inductance, 1.0},     {"mH", Dimension::Inductance, 1e-3},
    {"kg*m^2", Dimension::Inertia, 1.0},   {"g*cm^2", Dimension::Inertia, 1e-7},
    {"m/s", Dimension::Speed, 1.0},        {"mm/s", Dimension::Speed, 1e-3},
    {"mm/min", Dimension::Speed, 1e-3 / 60.0},
    {"m/s^2", Dimension::Acceleration, 1.0}, {"mm/s^2", Dimension::Acceleration, 1e-3},
    {"N*m/A", Dimension::TorqueConstant, 1.0}, {"V*s/rad", Dimension::TorqueConstant, 1.0},
    {"N*m*s/rad", Dimension::RotaryDamping, 1.0},
};

std::string accepted_units(Dimension dimension) {
    std::string out;
    for (const auto& u : kUnits) {
        if (u.dimension != dimension) continue;
        if (!out.empty()) out += ", ";
        out += u.symbol;
    }
    return out;
}

}  // namespace

const char* to_string(Dimension dimension) {
    switch (dimension) {
        case Dimension::Dimensionless: return "a plain number";
        case Dimension::Time: return "a time";
        case Dimension::Length: return "a length";
        case Dimension::Frequency: return "a frequency";
        case Dimension::Angle: return "an angle";
        case Dimension::Voltage: return "a voltage";
        case Dimension::Current: return "a current";
        case Dimension::Resistance: return "a resistance";
        case Dimension::Power: return "a power";
        case Dimension::Temperature: return "a temperature";
        case Dimension::ThermalResistance: return "a thermal resistance";
        case Dimension::HeatCapacity: return "a heat capacity";
        case Dimension::ThermalConductance: return "a thermal conductance";
        case Dimension::Torque: return "a torque";
        case Dimension::Inductance: return "an inductance";
        case Dimension::Inertia: return "an inertia";
        case Dimension::Speed: return "a speed";
        case Dimension::Acceleration: return "an acceleration";
        case Dimension::TorqueConstant: return "a torque constant";
        case Dimension::RotaryDamping: return "a rotary damping";
    }
    return "a quantity";
}

double parse_quantity(std::string_view text, Dimension dimension, std::string_view what) {
    const std::string original(text);
    while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
    while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
    double value = 0;
    const char* begin = text.data();
    if (!text.empty() && text.front() == '+') ++begin;
    auto [end, ec] = std::from_chars(begin, text.data() + text.size(), value);
    if (ec != std::errc() || text.empty()) {
        throw BadInput(std::string(what) + ": '" + original + "' is not a number" +
                       (dimension == Dimension::Dimensionless ? "" : " with a unit"));
    }
    if (!std::isfinite(value)) throw BadInput(std::string(what) + ": '" + original + "' is not finite");
    std::string unit(end, text.data() + text.size());
    while (!unit.empty() && unit.front() == ' ') unit.erase(0, 1);
    if (unit.empty()) {
        if (dimension == Dimension::Dimensionless) return value;
        throw BadInput(std::string(what) + ": '" + original + "' needs a unit (" + accepted_units(dimension) + ")");
    }
    for (const auto& u : kUnits) {
        if (unit != u.symbol) continue;
        if (u.dimension != dimension) {
            throw BadInput(std::string(what) + ": '" + original + "' is " + to_string(u.dimension) + ", expected " +
                           to_string(dimension) +
                           (dimension == Dimension::Dimensionless ? "" : " (" + accepted_units(dimension) + ")"));
        }
        return value * u.to_si;
    }
    throw BadInput(std::string(what) + ": unknown unit '" + unit + "' in '" + original + "'" +
                   (dimension == Dimension::Dimensionless ? " (expected a plain number)"
                                                          : " (expected " + accepted_units(dimension) + ")"));
}

double parse_seconds(std::string_view text, std::string_view what) {
    const double s = parse_quantity(text, Dimension::Time, what);
    if (s < 0) throw BadInput(std::string(what) + ": '" + std::string(text) + "' must not be negative");
    return s;
}

std::uint64_t ps_from_seconds(double seconds, std::string_view what) {
    if (!std::isfinite(seconds) || seconds < 0) {
        throw BadInput(std::string(what) + ": a time must be finite and not negative");
    }
    if (seconds > kMaxRunSeconds) {
        throw BadInput(std::string(what) + ": " + std::to_string(seconds) + " s is longer than the longest run (" +
                       std::to_string(static_cast<long long>(kMaxRunSeconds)) + " s)");
    }
    return static_cast<std::uint64_t>(std::llround(seconds * static_cast<double>(kPsPerSecond)));
}

std::uint64_t parse_duration_ps(std::string_view text, std::string_view what) {
    const double s = parse_seconds(text, what);
    if (s > kMaxRunSeconds) {
        throw BadInput(std::string(what) + ": '" + std::string(text) + "' is longer than the longest run (" +
                       std::to_string(static_cast<long long>(kMaxRunSeconds)) + " s)");
    }
    return ps_from_seconds(s, what);
}

std::int64_t checked_integer(double value, std::string_view what, std::int64_t min_value, std::int64_t max_value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.10g", value);
    if (!std::isfinite(value) || value != std::floor(value)) {
        throw BadInput(std::string(what) + ": " + text + " is not a whole number");
    }
    // Compare as doubles first: the range check must come before any cast.
    // The second check catches max_value near 2^63, which rounds up as a double.
    if (value < static_cast<double>(min_value) || value > static_cast<double>(max_value) ||
        static_cast<std::int64_t>(value) < min_value || static_cast<std::int64_t>(value) > max_value) {
        throw BadInput(std::string(what) + ": " + text + " is outside " + std::to_string(min_value) + ".." +
                       std::to_string(max_value));
    }
    return static_cast<std::int64_t>(value);
}

std::int64_t parse_integer(std::string_view text, std::string_view what, std::int64_t min_value, std::int64_t max_value) {
    const double value = parse_quantity(text, Dimension::Dimensionless, what);
    if (value != std::floor(value)) {
        throw BadInput(std::string(what) + ": '" + std::string(text) + "' is not a whole number");
    }
    if (value < static_cast<double>(min_value) || value > static_cast<double>(max_value)) {
        throw BadInput(std::string(what) + ": '" + std::string(text) + "' is outside " + std::to_string(min_value) +
                       ".." + std::to_string(max_value));
    }
    return checked_integer(value, what, min_value, max_value);
}

std::uint32_t parse_frequency_hz(std::string_view text, std::string_view what) {
    // A bare number of Hz is what avr-gcc users write for F_CPU.
    double hz = 0;
    try {
        hz = parse_quantity(text, Dimension::Dimensionless, what);
    } catch (const BadInput&) {
        hz = parse_quantity(text, Dimension::Frequency, what);
    }
    if (hz < kMinClockHz || hz > kMaxClockHz || std::fabs(hz - std::round(hz)) > 1e-6) {
        throw BadInput(std::string(what) + ": '" + std::string(text) + "' is not a whole number of Hz from 1 Hz to 64 MHz");
    }
    return static_cast<std::uint32_t>(std::llround(hz));
}

}  // namespace avrbench
