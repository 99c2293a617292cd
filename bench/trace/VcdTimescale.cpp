#include "trace/VcdTimescale.hpp"

#include <algorithm>
#include <stdexcept>

namespace avrbench {

namespace {

// __extension__ keeps -Wpedantic quiet about the GCC/Clang 128-bit integer.
__extension__ typedef unsigned __int128 Uint128;

std::uint64_t power_of_ten(int exponent) {
    std::uint64_t value = 1;
    for (int i = 0; i < exponent; ++i) value *= 10;
    return value;
}

// Smallest k with clock_hz | 10^k, or -1 when the clock has a prime factor other than 2 and 5.
int exponent_needed(std::uint32_t clock_hz) {
    int twos = 0;
    int fives = 0;
    while (clock_hz % 2 == 0) clock_hz /= 2, ++twos;
    while (clock_hz % 5 == 0) clock_hz /= 5, ++fives;
    return clock_hz == 1 ? std::max(twos, fives) : -1;
}

}  // namespace

VcdTimescale VcdTimescale::for_clocks(const std::vector<std::uint32_t>& clocks_hz) {
    int exponent = 0;
    for (const std::uint32_t clock_hz : clocks_hz) {
        if (clock_hz == 0) throw std::invalid_argument("VCD timescale: a clock of 0 Hz has no cycle period");
        const int needed = exponent_needed(clock_hz);
        if (needed < 0 || needed > kFinestExponent) return VcdTimescale(kFinestExponent, false);
        exponent = std::max(exponent, needed);
    }
    return VcdTimescale(exponent, true);
}

VcdTimescale::VcdTimescale(int exponent, bool exact)
    : exponent_(exponent), exact_(exact), units_per_second_(power_of_ten(exponent)) {
    if (exponent < 0 || exponent > kFinestExponent)
        throw std::invalid_argument("VCD timescale exponent must be 0..15, got " + std::to_string(exponent));
}

std::string VcdTimescale::text() const {
    // Unit 10^-k s is written as 10^(e-k) * 10^-e s with e the next multiple of 3.
    static const char* const kSuffix[] = {"s", "ms", "us", "ns", "ps", "fs"};
    const int group = (exponent_ + 2) / 3;
    const int multiplier_exponent = group * 3 - exponent_;
    return std::to_string(power_of_ten(multiplier_exponent)) + kSuffix[group];
}

std::uint64_t VcdTimescale::units_at(Cycle cycle, std::uint32_t clock_hz) const {
    if (clock_hz == 0) throw std::invalid_argument("VCD time: a clock of 0 Hz has no cycle period");
    // cycle < 2^64 and units_per_second <= 10^15 < 2^50, so the product fits 128 bits.
    const Uint128 scaled = static_cast<Uint128>(cycle) * units_per_second_;
    const Uint128 units = (scaled + clock_hz / 2) / clock_hz;  // exact when f | 10^k
    if (units > UINT64_MAX)
        throw std::overflow_error("VCD time of cycle " + std::to_string(cycle) + " at " +
                                  std::to_string(clock_hz) + " Hz does not fit 64 bits in units of " + text());
    return static_cast<std::uint64_t>(units);
}

std::uint64_t VcdTimescale::units_per_cycle(std::uint32_t clock_hz) const {
    if (clock_hz == 0 || units_per_second_ % clock_hz != 0) return 0;
    return units_per_second_ / clock_hz;
}

}  // namespace avrbench
