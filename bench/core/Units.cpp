#include "core/Units.hpp"

#include <charconv>
#include <cmath>
#include <utility>

#include "core/Errors.hpp"

namespace avrbench {
namespace {

struct NumberAndUnit {
    double value;
    std::string unit;
};

NumberAndUnit split(std::string_view text, std::string_view what) {
    while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
    while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
    double value = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || text.empty()) {
        throw BadInput(std::string(what) + ": '" + std::string(text) + "' is not a number with a unit");
    }
    std::string unit(end, text.data() + text.size());
    while (!unit.empty() && unit.front() == ' ') unit.erase(0, 1);
    if (!std::isfinite(value) || value < 0) {
        throw BadInput(std::string(what) + ": '" + std::string(text) + "' must be a non-negative number");
    }
    return {value, unit};
}

}  // namespace

double parse_seconds(std::string_view text, std::string_view what) {
    const auto [value, unit] = split(text, what);
    static constexpr std::pair<const char*, double> kUnits[] = {
        {"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}, {"ns", 1e-9}, {"min", 60.0},
    };
    for (const auto& [name, scale] : kUnits) {
        if (unit == name) return value * scale;
    }
    throw BadInput(std::string(what) + ": '" + std::string(text) +
                   "' needs a time unit (s, ms, us, ns, min)");
}

std::uint32_t parse_frequency_hz(std::string_view text, std::string_view what) {
    const auto [value, unit] = split(text, what);
    double scale = 0;
    if (unit.empty() || unit == "Hz") scale = 1.0;
    else if (unit == "kHz") scale = 1e3;
    else if (unit == "MHz") scale = 1e6;
    else throw BadInput(std::string(what) + ": '" + std::string(text) + "' needs a frequency unit (Hz, kHz, MHz)");
    const double hz = value * scale;
    if (hz < 1 || hz > 4e9 || std::fabs(hz - std::round(hz)) > 1e-6) {
        throw BadInput(std::string(what) + ": '" + std::string(text) + "' is not a whole number of Hz in range");
    }
    return static_cast<std::uint32_t>(std::llround(hz));
}

}  // namespace avrbench
