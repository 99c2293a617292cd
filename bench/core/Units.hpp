// Quantities with units as users write them: "2s", "250us", "16MHz",
// "1.9us", "200mm", "4.7kohm". One parser so the CLI, board files and
// scenarios agree. Values are returned in SI units.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace avrbench {

enum class Dimension {
    Dimensionless,  // a bare number: counts, ratios, or a unit carried by the name (steps_per_mm)
    Time,           // s
    Length,         // m
    Frequency,      // Hz
    Angle,          // rad
    Voltage,        // V
    Current,        // A
    Resistance,     // ohm
    Power,          // W
    Temperature,    // degC (offset scale kept as users write it: 25degC -> 25)
    ThermalResistance,  // K/W
    HeatCapacity,       // J/K
    ThermalConductance, // W/K
    Torque,             // N*m
    Inductance,         // H
    Inertia,            // kg*m^2
    Speed,              // m/s
    Acceleration,       // m/s^2
    TorqueConstant,     // N*m/A (= V*s/rad, the back-EMF constant)
    RotaryDamping,      // N*m*s/rad (viscous friction)
};

const char* to_string(Dimension dimension);

// Parses "<number><unit>" (a space between is allowed) into SI units of
// `dimension`. A bare number is accepted only for Dimensionless. Throws
// BadInput naming `what` on a bad number, a unit of another dimension, or an
// unknown unit; the message lists the units the dimension accepts.
double parse_quantity(std::string_view text, Dimension dimension, std::string_view what);

// Seconds from "2s", "250ms", "100us", "500ns", "1.5min".
double parse_seconds(std::string_view text, std::string_view what);

// Picoseconds from a time as parse_seconds reads it, rejecting spans longer
// than kMaxRunSeconds (core/Time.hpp) so that cycle counts never overflow.
std::uint64_t parse_duration_ps(std::string_view text, std::string_view what);

// Picoseconds from seconds (rounded to the nearest), with the same checks:
// finite, not negative, at most kMaxRunSeconds. `what` names the value.
std::uint64_t ps_from_seconds(double seconds, std::string_view what);

// A whole number from user text ("1600", "1.6e3"), checked: it must be
// integral and within [min_value, max_value]; otherwise BadInput naming `what`.
// The one way user numbers become integers (never a bare cast: converting an
// out-of-range double to an integer is undefined behaviour).
std::int64_t parse_integer(std::string_view text, std::string_view what, std::int64_t min_value, std::int64_t max_value);
// The same check for a value already parsed as a double.
std::int64_t checked_integer(double value, std::string_view what, std::int64_t min_value, std::int64_t max_value);

// Hertz from "16MHz", "20 MHz", "32768Hz", or a bare number of Hz.
// MCU clocks the bench accepts, wherever they come from (--freq, a board
// file, an ELF's .mmcu section): no AVR is specified above 32 MHz (XMEGA);
// 64 MHz leaves room for overclocking experiments and keeps a second of
// simulated time bounded.
inline constexpr std::uint32_t kMinClockHz = 1;
inline constexpr std::uint32_t kMaxClockHz = 64'000'000;
std::uint32_t parse_frequency_hz(std::string_view text, std::string_view what);

}  // namespace avrbench
