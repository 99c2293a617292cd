// simavr's avr_core_watch_write() logs a write above RAMEND as a crash but
// still stores the byte at avr->data[addr], past the end of a buffer of
// RAMEND + 1 bytes: a firmware bug (or a Mega ELF on an ATtiny) corrupts the
// host's heap. Growing the buffer to the whole 16-bit data space turns those
// writes into harmless guard-space writes while simavr's crash is reported.
#include <cstdlib>
#include <cstring>
#include <new>

#include "periph/Fixes.hpp"

namespace avrbench {

std::unique_ptr<Fix> install_memory_guard(avr_t* avr) {
    // _avr_push_addr writes up to 3 bytes below SP, which wraps at 16 bits;
    // 64 KiB + slack covers every address a firmware can form.
    constexpr std::size_t kDataSpaceBytes = 0x10000 + 16;
    const std::size_t used = static_cast<std::size_t>(avr->ramend) + 1;
    if (used < kDataSpaceBytes) {
        auto* grown = static_cast<std::uint8_t*>(std::realloc(avr->data, kDataSpaceBytes));
        if (grown == nullptr) throw std::bad_alloc();
        std::memset(grown + used, 0, kDataSpaceBytes - used);
        avr->data = grown;
    }
    return nullptr;
}

}  // namespace avrbench
