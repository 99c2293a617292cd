// Hooks on one I/O register of an MCU's core, chained in front of whatever
// simavr (or an earlier hook) does there: the core's fixes and the layers
// above (the wiring's port watch) intercept register accesses the same way.
// Undo them newest first (destroy in reverse order of creation).
#pragma once

#include <cstdint>

extern "C" {
#include <sim_avr.h>
}

namespace avrbench {

// Chains a bench handler in front of (or after) the write handler simavr
// installed on one I/O register. The handler receives `this`; call
// `write_original()` to let simavr do its part.
class IoWriteHook {
public:
    using Handler = void (*)(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);

    IoWriteHook(avr_t* avr, avr_io_addr_t data_address, Handler handler, void* context);
    ~IoWriteHook();
    IoWriteHook(const IoWriteHook&) = delete;
    IoWriteHook& operator=(const IoWriteHook&) = delete;

    // Inline: on the pin and timer registers this runs for every access.
    void write_original(avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        if (original_ != nullptr) {
            original_(avr, addr, value, original_param_);
        } else {
            avr_core_watch_write(avr, addr, value);
        }
    }
    void* context() const { return context_; }

private:
    static void trampoline(avr_t* avr, avr_io_addr_t addr, std::uint8_t value, void* param);

    avr_t* avr_;
    avr_io_addr_t address_;
    Handler handler_;
    void* context_;
    avr_io_write_t original_;
    void* original_param_;
};

// Same for reads.
class IoReadHook {
public:
    using Handler = std::uint8_t (*)(IoReadHook& hook, avr_t* avr, avr_io_addr_t addr);

    IoReadHook(avr_t* avr, avr_io_addr_t data_address, Handler handler, void* context);
    ~IoReadHook();
    IoReadHook(const IoReadHook&) = delete;
    IoReadHook& operator=(const IoReadHook&) = delete;

    std::uint8_t read_original(avr_t* avr, avr_io_addr_t addr) {
        return original_ != nullptr ? original_(avr, addr, original_param_) : avr_core_watch_read(avr, addr);
    }
    void* context() const { return context_; }

private:
    static std::uint8_t trampoline(avr_t* avr, avr_io_addr_t addr, void* param);

    avr_t* avr_;
    avr_io_addr_t address_;
    Handler handler_;
    void* context_;
    avr_io_read_t original_;
    void* original_param_;
};

}  // namespace avrbench
