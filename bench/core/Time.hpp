// Simulated time. Everything inside a run is counted in cycles of the MCU that
// owns them; seconds appear only at the edges (reports, VCD, user input).
//
// Where several MCUs with different clocks share a deadline, the deadline is
// held as integer picoseconds (Picoseconds) and turned into each MCU's cycle
// by rounding up (Lockstep's cycle_at_ps). For integers, cycle >=
// ceil(t*f/1e12) holds exactly when floor(cycle*1e12/f) >= t, so "has the
// board reached t" is an exact integer comparison whichever side it is asked
// from: a loop that runs to t and then compares with t always sees it reached.
// Never compare simulated times as doubles in a loop.
#pragma once

#include <cstdint>

namespace avrbench {

using Cycle = std::uint64_t;
using Picoseconds = std::uint64_t;

constexpr Picoseconds kPsPerSecond = 1'000'000'000'000ULL;
constexpr Picoseconds kPsPerMs = 1'000'000'000ULL;

// The longest simulated span one run accepts: 10^6 s (11.6 days). 2^64 ps is
// 1.8e7 s, so sums of two spans within this limit never overflow.
constexpr double kMaxRunSeconds = 1e6;

inline double seconds_from_ps(Picoseconds ps) { return static_cast<double>(ps) * 1e-12; }

// Saturating addition, for deadlines "now + span".
inline Picoseconds add_ps(Picoseconds a, Picoseconds b) { return a > ~Picoseconds{0} - b ? ~Picoseconds{0} : a + b; }

}  // namespace avrbench
