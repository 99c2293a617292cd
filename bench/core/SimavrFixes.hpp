// Corrections applied to every simavr core the bench creates, where simavr 1.6
// departs from the datasheet or from deterministic virtual time. Each is
// listed in docs/FIDELITY.md with the test that pins it.
#pragma once

#include <memory>
#include <vector>

struct avr_t;

namespace avrbench {

// Installs all corrections on a freshly initialised core:
//  - memory safety: simavr logs a write above RAMEND as a crash but still
//    performs it (avr_core_watch_write), past the end of its data buffer,
//    corrupting the host's heap; the buffer is grown to the full 64 KiB data
//    space so such writes land in guard space while the crash is reported;
//  - SLEEP never waits on the wall clock (simavr's raw sleep callback usleep()s);
//  - the UARTs' poll-sleep (a usleep(1) on every UCSRnA read) and stdout echo
//    are switched off;
//  - USART frame length: simavr counts a parity bit in every frame (11 bit
//    times for 8N1); the datasheet frame is start + data + parity-if-enabled
//    + stop bits (ATmega328P §19.4 "Frame Formats": 8N1 = 10 bits), and it is
//    recomputed whenever UBRR, U2X, UCSZ, UPM or USBS change, not only on a
//    UBRR write.
// The object owns the hooks' state and must live as long as the core.
class SimavrFixes {
public:
    explicit SimavrFixes(avr_t* avr);
    ~SimavrFixes();
    SimavrFixes(const SimavrFixes&) = delete;
    SimavrFixes& operator=(const SimavrFixes&) = delete;

    struct UartFrameFix;

private:
    std::vector<std::unique_ptr<UartFrameFix>> uart_frame_fixes_;
};

}  // namespace avrbench
