// USART on the ATmega32 (and ATmega16/8): UCSRC and UBRRH share one I/O
// location; "the URSEL bit selects between accessing the UCSRC or the UBRRH
// Register" when it is written (ATmega32 datasheet, "Accessing UBRRH/UCSRC
// Registers"). simavr 1.6 stores both in one byte, so the UBRRH = 0 that
// firmware writes after the frame format turns an 8N1 frame into 5 data bits
// (7 bit times). Here the two are kept apart: the location holds UBRRH (what
// a single read returns) and the UCSRC the firmware wrote is kept apart for
// uart_frame (frame length, the levels drawn on TxD/RxD).
#include <vector>

extern "C" {
#include <avr_uart.h>
}

#include "periph/Fixes.hpp"

namespace avrbench {
namespace {

class UartUrsel final : public Fix {
public:
    UartUrsel(avr_t* avr, avr_uart_t* uart) : uart_(uart) {
        const avr_io_addr_t regs[] = {static_cast<avr_io_addr_t>(uart->ubrrl.reg),
                                      static_cast<avr_io_addr_t>(uart->ubrrh.reg),
                                      static_cast<avr_io_addr_t>(uart->u2x.reg),
                                      static_cast<avr_io_addr_t>(uart->ucsz2.reg)};
        std::vector<avr_io_addr_t> done;
        for (auto r : regs) {
            bool seen = false;
            for (auto d : done) seen = seen || d == r;
            if (seen || r < 0x20) continue;
            done.push_back(r);
            hooks_.push_back(std::make_unique<IoWriteHook>(avr, r, &on_write, this));
        }
        set_uart_ucsrc_shadow(uart_, &ucsrc_);
    }
    ~UartUrsel() override { set_uart_ucsrc_shadow(uart_, nullptr); }
    UartUrsel(const UartUrsel&) = delete;
    UartUrsel& operator=(const UartUrsel&) = delete;

private:
    static void on_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<UartUrsel*>(hook.context());
        avr_uart_t* u = self->uart_;
        const auto shared = static_cast<avr_io_addr_t>(u->ubrrh.reg);
        if (addr == shared) {
            if (value & 0x80) {
                self->ucsrc_ = value;  // URSEL = 1: UCSRC
            } else {
                self->ubrrh_ = static_cast<std::uint8_t>(value & 0x0F);
            }
            hook.write_original(avr, addr, value);
            avr->data[shared] = self->ubrrh_;
        } else {
            hook.write_original(avr, addr, value);
        }
        u->cycles_per_byte = static_cast<avr_cycle_count_t>(uart_frame(avr, u).cycles_per_bit) *
                             static_cast<avr_cycle_count_t>(uart_frame(avr, u).bits());
    }

    avr_uart_t* uart_;
    std::uint8_t ucsrc_ = 0x86;  // reset value: 8N1 (URSEL reads one, UCSZ1:0 = 11)
    std::uint8_t ubrrh_ = 0;
    std::vector<std::unique_ptr<IoWriteHook>> hooks_;
};

class UartUrsels final : public Fix {
public:
    std::vector<std::unique_ptr<UartUrsel>> all;
};

}  // namespace

std::unique_ptr<Fix> install_uart_ursel(avr_t* avr) {
    auto fix = std::make_unique<UartUrsels>();
    for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind == nullptr || std::string_view(io->kind) != "uart") continue;
        auto* uart = reinterpret_cast<avr_uart_t*>(io);
        if (uart->ubrrh.reg == 0 || uart->ubrrh.reg != uart->ucsz.reg) continue;  // separate registers
        fix->all.push_back(std::make_unique<UartUrsel>(avr, uart));
    }
    if (fix->all.empty()) return nullptr;
    return fix;
}

}  // namespace avrbench
