// The firmware fuzz target's mutator: stimulus/GcodeMutator with libFuzzer's
// own byte-level mutator as the fallback.
#pragma once

#include <cstddef>
#include <cstdint>

#include "stimulus/GcodeMutator.hpp"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace avrbench::fuzz {

inline std::size_t mutate_gcode(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned seed) {
    return avrbench::mutate_gcode(data, size, max_size, seed, &LLVMFuzzerMutate);
}

}  // namespace avrbench::fuzz
