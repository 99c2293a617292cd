// The VCD time unit for a set of clock domains, and the exact cycle -> time conversion.
//
// VCD timestamps are integers in a unit of 1, 10 or 100 s/ms/us/ns/ps/fs. A cycle
// of a clock f lasts 1/f s, which is a whole number of units 10^-k s exactly when
// f divides 10^k, i.e. when f = 2^a * 5^b with a, b <= k. The coarsest such unit
// keeps timestamps short: 16 MHz (2^10 * 5^6) needs 100ps, 20 MHz (2^8 * 5^7)
// 10ns, both together 100ps. A clock with another prime factor (14.7456 MHz =
// 2^16 * 3^2 * 5^2) has no exact unit; then the finest (1fs) is used, times are
// rounded to the nearest fs, and exact() is false so callers can warn.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "trace/Timeline.hpp"

namespace avrbench {

class VcdTimescale {
public:
    static constexpr int kFinestExponent = 15;  // 1 fs, the finest unit VCD has

    // The coarsest unit in which every clock's cycle is a whole number of units.
    static VcdTimescale for_clocks(const std::vector<std::uint32_t>& clocks_hz);

    // unit = 10^-exponent s
    explicit VcdTimescale(int exponent, bool exact = true);

    int exponent() const { return exponent_; }
    bool exact() const { return exact_; }
    std::uint64_t units_per_second() const { return units_per_second_; }
    // As written after $timescale, e.g. "100ps".
    std::string text() const;

    // Time of the start of `cycle` of a `clock_hz` clock, in units, computed in
    // 128-bit integers (no floating point). Rounded to the nearest unit when the
    // period is not a whole number of units. Throws std::overflow_error when the
    // time does not fit 64 bits (at 1fs: after about 5 hours of simulated time).
    std::uint64_t units_at(Cycle cycle, std::uint32_t clock_hz) const;

    // Units per cycle of `clock_hz`, or 0 when that is not a whole number.
    std::uint64_t units_per_cycle(std::uint32_t clock_hz) const;

private:
    int exponent_;
    bool exact_;
    std::uint64_t units_per_second_;
};

}  // namespace avrbench
