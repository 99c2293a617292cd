// Simulated time. Everything inside a run is counted in cycles of the MCU that
// owns them; seconds appear only at the edges (reports, VCD, user input).
#pragma once

#include <cstdint>

namespace avrbench {

using Cycle = std::uint64_t;

}  // namespace avrbench
