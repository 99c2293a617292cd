#include "core/SimavrFixes.hpp"

#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

extern "C" {
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_io.h>
}

namespace avrbench {
namespace {

void sleep_in_virtual_time(avr_t* /*avr*/, avr_cycle_count_t /*how_long*/) {
    // simavr's run loop already advances avr->cycle past the sleep; the raw
    // callback would additionally usleep() to stay in step with the wall clock.
}

// Datasheet frame length in bit times: start + data + parity + stop
// (ATmega328P §19.4, UCSZn2:0 table 19-7, UPMn1:0 table 19-5, USBSn table 19-6).
avr_cycle_count_t uart_cycles_per_frame(avr_t* avr, const avr_uart_t* p) {
    const std::uint32_t ubrr =
        avr_regbit_get(avr, p->ubrrl) | (static_cast<std::uint32_t>(avr_regbit_get(avr, p->ubrrh)) << 8);
    std::uint32_t cycles_per_bit = (ubrr + 1) * 8;  // U2X = 1: f/(8(UBRR+1)) baud
    if (!avr_regbit_get(avr, p->u2x)) cycles_per_bit *= 2;  // U2X = 0: f/(16(UBRR+1))
    static constexpr int kDataBits[8] = {5, 6, 7, 8, 8, 8, 8, 9};  // 4..6 reserved: treat as 8
    const int ucsz = avr_regbit_get(avr, p->ucsz) | (avr_regbit_get(avr, p->ucsz2) << 2);
    // UPMn1 is bit 5 of UCSRnC on the megaAVRs simavr models; any UPM != 0 adds a bit.
    const bool parity = p->r_ucsrc != 0 && ((avr->data[p->r_ucsrc] >> 4) & 0x3) != 0;
    const int stop_bits = 1 + avr_regbit_get(avr, p->usbs);
    const int bits = 1 + kDataBits[ucsz & 7] + (parity ? 1 : 0) + stop_bits;
    return static_cast<avr_cycle_count_t>(cycles_per_bit) * static_cast<avr_cycle_count_t>(bits);
}

}  // namespace

// Wraps the write handler simavr installed on one I/O register so the UART's
// frame length is recomputed after simavr has done its own work.
struct SimavrFixes::UartFrameFix {
    avr_uart_t* uart;
    avr_io_write_t original;
    void* original_param;
};

namespace {

void uart_frame_register_write(avr_t* avr, avr_io_addr_t addr, std::uint8_t v, void* param) {
    auto* fix = static_cast<SimavrFixes::UartFrameFix*>(param);
    if (fix->original != nullptr) {
        fix->original(avr, addr, v, fix->original_param);
    } else {
        avr_core_watch_write(avr, addr, v);
    }
    fix->uart->cycles_per_byte = uart_cycles_per_frame(avr, fix->uart);
}

void fix_uart(avr_t* avr, avr_uart_t* uart,
              std::vector<std::unique_ptr<SimavrFixes::UartFrameFix>>& fixes) {
    std::uint32_t flags = 0;  // no POLL_SLEEP (wall-clock usleep), no STDIO echo
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS(uart->name), &flags);

    const std::vector<std::uint32_t> addresses = {uart->ubrrl.reg, uart->ubrrh.reg, uart->u2x.reg,
                                                  uart->ucsz.reg,  uart->ucsz2.reg, uart->usbs.reg,
                                                  uart->r_ucsrc};
    for (std::size_t i = 0; i < addresses.size(); ++i) {
        const std::uint32_t addr = addresses[i];
        if (addr < 32) continue;  // regbit not present on this core
        bool seen = false;
        for (std::size_t j = 0; j < i; ++j) seen = seen || addresses[j] == addr;
        if (seen) continue;
        auto& slot = avr->io[AVR_DATA_TO_IO(addr)].w;
        fixes.push_back(std::make_unique<SimavrFixes::UartFrameFix>(
            SimavrFixes::UartFrameFix{uart, slot.c, slot.param}));
        slot.c = &uart_frame_register_write;
        slot.param = fixes.back().get();
    }
}

}  // namespace

SimavrFixes::~SimavrFixes() = default;

SimavrFixes::SimavrFixes(avr_t* avr) {
    // Data addresses are 16 bits wide; _avr_push_addr may write up to 3 bytes
    // below a wrapped SP. 64 KiB + slack covers every address a firmware can form.
    constexpr std::size_t kDataSpaceBytes = 0x10000 + 16;
    const std::size_t used = static_cast<std::size_t>(avr->ramend) + 1;
    if (used < kDataSpaceBytes) {
        auto* grown = static_cast<std::uint8_t*>(std::realloc(avr->data, kDataSpaceBytes));
        if (grown == nullptr) throw std::bad_alloc();
        std::memset(grown + used, 0, kDataSpaceBytes - used);
        avr->data = grown;
    }
    avr->sleep = &sleep_in_virtual_time;
    for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind != nullptr && std::strcmp(io->kind, "uart") == 0) {
            fix_uart(avr, reinterpret_cast<avr_uart_t*>(io), uart_frame_fixes_);
        }
    }
}

}  // namespace avrbench
