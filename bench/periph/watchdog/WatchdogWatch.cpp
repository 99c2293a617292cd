#include "periph/watchdog/WatchdogWatch.hpp"

extern "C" {
#include <avr_watchdog.h>
}

#include "periph/Fix.hpp"

namespace avrbench {

WatchdogWatch::WatchdogWatch(avr_t* avr) : avr_(avr) {
    // First in the core's I/O modules: it sees each WDR's ioctl and passes it on.
    module_.io.kind = "watchdog-watch";
    module_.io.ioctl = &WatchdogWatch::on_ioctl;
    module_.io.avr = avr;
    module_.io.next = avr->io_port;
    module_.watch = this;
    avr->io_port = &module_.io;
    if (avr_io_t* io = find_io_module(avr, "watchdog")) {
        auto* wdt = reinterpret_cast<avr_watchdog_t*>(io);
        control_hook_ = std::make_unique<IoWriteHook>(avr, static_cast<avr_io_addr_t>(wdt->wde.reg), &on_control_write, this);
    }
}

WatchdogWatch::~WatchdogWatch() {
    control_hook_.reset();
    for (avr_io_t** link = &avr_->io_port; *link != nullptr; link = &(*link)->next) {
        if (*link == &module_.io) {
            *link = module_.io.next;
            break;
        }
    }
}

int WatchdogWatch::on_ioctl(avr_io_t* io, std::uint32_t ctl, void*) {
    if (ctl == AVR_IOCTL_WATCHDOG_RESET) reinterpret_cast<Module*>(io)->watch->last_wdr_ = io->avr->cycle;
    return -1;  // not answered: the watchdog module does the WDR
}

void WatchdogWatch::on_control_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    static_cast<WatchdogWatch*>(hook.context())->last_control_write_ = avr->cycle;
    hook.write_original(avr, addr, value);
}

void WatchdogWatch::reset() {
    last_wdr_.reset();
    last_control_write_.reset();
}

bool WatchdogWatch::requested(std::uint32_t pc_bytes) const {
    if (!last_control_write_ || (last_wdr_ && *last_wdr_ > *last_control_write_)) return false;
    if (pc_bytes + 3 >= avr_->flashend + 1u) return false;
    const unsigned word = avr_->flash[pc_bytes] | (avr_->flash[pc_bytes + 1] << 8);
    // RJMP .-2 (1100 kkkk kkkk kkkk, k = -1), or JMP to its own address
    // (1001 010k kkkk 110k + 16 bits, a word address): AVR Instruction Set Manual.
    if (word == 0xCFFF) return true;
    if ((word & 0xFE0E) == 0x940C) {
        const std::uint32_t target_words =
            (static_cast<std::uint32_t>((word >> 3) & 0x3E) | (word & 1)) << 16 |
            static_cast<std::uint32_t>(avr_->flash[pc_bytes + 2] | (avr_->flash[pc_bytes + 3] << 8));
        return target_words * 2 == pc_bytes;
    }
    return false;
}

}  // namespace avrbench
