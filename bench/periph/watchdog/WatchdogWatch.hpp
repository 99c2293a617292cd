// Whether a watchdog reset is one the firmware asked for. The documented way
// to reset an AVR from software is to enable the watchdog with a short
// time-out and spin until it fires (avr-libc's <avr/wdt.h> notes, Arduino's
// and Klipper's reset command: wdt_enable(WDTO_15MS); for (;;) {}); a reset
// the firmware did not ask for is a watchdog that fired because the firmware
// stopped serving it (hung). The rule (docs/CLI.md, "Findings"): asked for
// when no WDR ran since the firmware last wrote the watchdog's control
// register (wdt_enable runs its WDR before its writes) and the CPU, when it
// fired, was executing a jump to itself. A firmware that hangs in such a
// loop after serving its watchdog with WDR, or in any loop that does work,
// is not asking.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "core/IoHook.hpp"
#include "core/Time.hpp"

namespace avrbench {

class WatchdogWatch {
public:
    explicit WatchdogWatch(avr_t* avr);
    ~WatchdogWatch();
    WatchdogWatch(const WatchdogWatch&) = delete;
    WatchdogWatch& operator=(const WatchdogWatch&) = delete;

    // At a watchdog reset: whether the firmware asked for it, the CPU having
    // been at byte address `pc_bytes` when the watchdog fired.
    bool requested(std::uint32_t pc_bytes) const;
    // A new boot starts: what the last one did is forgotten.
    void reset();

private:
    static int on_ioctl(avr_io_t* io, std::uint32_t ctl, void* param);
    static void on_control_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);

    struct Module {
        avr_io_t io{};  // first: the core's io_port list holds its address
        WatchdogWatch* watch = nullptr;
    };
    avr_t* avr_;
    Module module_;
    std::unique_ptr<IoWriteHook> control_hook_;
    std::optional<Cycle> last_wdr_;
    std::optional<Cycle> last_control_write_;
};

}  // namespace avrbench
