// USART corrections:
//  - AVR_UART_FLAG_POLL_SLEEP (default on) usleep(1)s on every UCSRnA read
//    while idle, and AVR_UART_FLAG_STDIO echoes output lines to stdout: both off;
//  - frame length: simavr counts a parity bit in every frame (8N1 = 11 bit
//    times); the datasheet frame is start + data + parity-if-enabled + stop
//    (ATmega328P §19.4, 8N1 = 10 bits). simavr also recomputes it only on a
//    UBRRnL write; here it follows every write to UBRRnL/H, UCSRnA/B/C.
#include <string_view>
#include <vector>

extern "C" {
#include <avr_uart.h>
}

#include "core/AvrContext.hpp"
#include "periph/Fixes.hpp"

namespace avrbench {

// Bit times per frame (ATmega328P §19.4; UCSZn2:0 table 19-7, UPMn1:0 table
// 19-5, USBSn table 19-6) and cycles per bit (§19.3.1 table 19-1).
namespace {

// The UCSRC shadows of USARTs whose UCSRC shares UBRRH's location, kept in
// the core's AvrContext by the USART they belong to.
struct UcsrcShadow {};

}  // namespace

void set_uart_ucsrc_shadow(const avr_uart_t* uart, const std::uint8_t* ucsrc) {
    AvrContext* context = AvrContext::of(uart->io.avr);
    if (context == nullptr) return;
    if (ucsrc == nullptr) {
        context->remove<UcsrcShadow>(uart);
    } else {
        context->add<UcsrcShadow>(uart, ucsrc);
    }
}

UartFrame uart_frame(avr_t* avr, const avr_uart_t* p) {
    const std::uint8_t* shadow = AvrContext::find_in<UcsrcShadow, const std::uint8_t>(avr, p);
    const std::uint32_t ubrr =
        avr_regbit_get(avr, p->ubrrl) | (static_cast<std::uint32_t>(avr_regbit_get(avr, p->ubrrh)) << 8);
    UartFrame f;
    f.cycles_per_bit = (ubrr + 1) * 8;                          // U2X = 1: f/(8(UBRR+1)) baud
    if (!avr_regbit_get(avr, p->u2x)) f.cycles_per_bit *= 2;    // U2X = 0: f/(16(UBRR+1))
    static constexpr int kDataBits[8] = {5, 6, 7, 8, 8, 8, 8, 9};  // 4..6 reserved: treat as 8
    // UCSZn1:0 are bits 2:1, USBSn bit 3 and UPMn1:0 bits 5:4 of UCSRnC on
    // every megaAVR simavr models (UPM: 00 none, 10 even, 11 odd; 01
    // reserved: a parity bit all the same, even).
    const std::uint8_t ucsrc = shadow != nullptr ? *shadow : p->r_ucsrc != 0 ? avr->data[p->r_ucsrc] : 0x06;
    const int ucsz = ((ucsrc >> 1) & 0x3) | (avr_regbit_get(avr, p->ucsz2) << 2);
    f.data_bits = kDataBits[ucsz & 7];
    f.parity = (ucsrc >> 4) & 0x3;
    f.stop_bits = 1 + ((ucsrc >> 3) & 1);
    return f;
}

UartFrameLevels uart_frame_levels(const UartFrame& frame, std::uint32_t data) {
    UartFrameLevels out;
    auto put = [&out](bool high) { out.high[static_cast<std::size_t>(out.count++)] = high; };
    put(false);
    bool ones_odd = false;
    for (int i = 0; i < frame.data_bits; ++i) {
        const bool one = ((data >> i) & 1) != 0;
        ones_odd = ones_odd != one;
        put(one);
    }
    if (frame.parity == 3) {
        put(!ones_odd);
    } else if (frame.parity != 0) {
        put(ones_odd);
    }
    for (int i = 0; i < frame.stop_bits; ++i) put(true);
    return out;
}

namespace {

avr_cycle_count_t uart_cycles_per_frame(avr_t* avr, const avr_uart_t* p) {
    const UartFrame f = uart_frame(avr, p);
    return static_cast<avr_cycle_count_t>(f.cycles_per_bit) * static_cast<avr_cycle_count_t>(f.bits());
}

class UartFraming final : public Fix {
public:
    void add(avr_t* avr, avr_uart_t* uart) {
        const std::uint32_t registers[] = {uart->ubrrl.reg, uart->ubrrh.reg, uart->u2x.reg,  uart->ucsz.reg,
                                           uart->ucsz2.reg, uart->usbs.reg,  uart->r_ucsrc};
        std::vector<std::uint32_t> done;
        for (std::uint32_t reg : registers) {
            if (reg < 32) continue;  // regbit not present on this core
            bool seen = false;
            for (std::uint32_t d : done) seen = seen || d == reg;
            if (seen) continue;
            done.push_back(reg);
            hooks_.push_back(std::make_unique<IoWriteHook>(avr, static_cast<avr_io_addr_t>(reg), &on_write, uart));
        }
    }

private:
    static void on_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        hook.write_original(avr, addr, value);
        auto* uart = static_cast<avr_uart_t*>(hook.context());
        uart->cycles_per_byte = uart_cycles_per_frame(avr, uart);
    }

    std::vector<std::unique_ptr<IoWriteHook>> hooks_;
};

}  // namespace

std::unique_ptr<Fix> install_uart_framing(avr_t* avr) {
    auto fix = std::make_unique<UartFraming>();
    for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind == nullptr || std::string_view(io->kind) != "uart") continue;
        auto* uart = reinterpret_cast<avr_uart_t*>(io);
        std::uint32_t flags = 0;  // no POLL_SLEEP (wall-clock usleep), no STDIO echo
        avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS(uart->name), &flags);
        fix->add(avr, uart);
    }
    return fix;
}

}  // namespace avrbench
