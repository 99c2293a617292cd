// The structure-aware G-code mutator (stimulus/GcodeMutator) as an AFL++
// custom mutator library (AFL++'s docs, custom_mutators.md: afl_custom_init,
// afl_custom_fuzz, afl_custom_deinit). `avrbench fuzz --engine afl` loads it
// with AFL_CUSTOM_MUTATOR_LIBRARY; AFL++'s own havoc stays on beside it and
// supplies the byte-level changes (so no byte-level fallback here).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

#include "stimulus/GcodeMutator.hpp"

namespace {

struct MutatorState {
    unsigned seed;
    std::vector<std::uint8_t> buffer;
};

}  // namespace

extern "C" {

void* afl_custom_init(void* /*afl_state*/, unsigned int seed) { return new (std::nothrow) MutatorState{seed, {}}; }

std::size_t afl_custom_fuzz(void* data, std::uint8_t* buf, std::size_t buf_size, std::uint8_t** out_buf,
                            std::uint8_t* /*add_buf*/, std::size_t /*add_buf_size*/, std::size_t max_size) {
    auto* state = static_cast<MutatorState*>(data);
    state->buffer.assign(buf, buf + buf_size);
    state->buffer.resize(std::max(max_size, buf_size));
    // Each call its own seed, so the same parent gives different children.
    const unsigned seed = state->seed++;
    const std::size_t size = avrbench::mutate_gcode(state->buffer.data(), buf_size, max_size, seed, nullptr);
    *out_buf = state->buffer.data();
    return size;
}

void afl_custom_deinit(void* data) { delete static_cast<MutatorState*>(data); }

}  // extern "C"
