// USART transmitter: the double-buffered UDR (ATmega328P §20.6 "Data
// Transmission - The USART Transmitter", §20.6.3 "Transmitter Flags and
// Interrupts"; ATmega2560 §22.6; ATmega32 "USART").
//
// simavr 1.6 has no transmit buffer: UDRE stays 0 until the frame in the
// shift register is out, and TXC rises at the same moment; a polled or
// UDRE-interrupt-driven stream leaves one frame plus the firmware's reaction
// time apart instead of exactly one frame. Its UDRE interrupt is re-raised
// once per frame time instead of as long as UDRE and UDRIE are set.
// Here a UDR write goes to the shift register at once when it is idle (UDRE
// stays one: the buffer is empty again) or waits in the buffer (UDRE = 0)
// until the stop bit of the frame being sent; TXC is set when a frame ends
// with nothing in the buffer. The byte is announced on UART_IRQ_OUTPUT when
// its start bit goes out (the bench's Uart stamps it with that cycle).
// The receiver is simavr's. TXEN is cleared at reset (simavr sets it).
#include <string_view>
#include <vector>

extern "C" {
#include <avr_uart.h>
#include <sim_cycle_timers.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include "core/fixes/Fixes.hpp"
#include "core/fixes/Interrupts.hpp"

namespace avrbench {
namespace {

class UartTransmitter;
Registry<avr_io_t, UartTransmitter>& tx_registry() {
    static Registry<avr_io_t, UartTransmitter> r;
    return r;
}

class UartTransmitter final : public Fix {
public:
    UartTransmitter(avr_t* avr, avr_uart_t* uart) : avr_(avr), uart_(uart) {
        udr_hook_ = std::make_unique<IoWriteHook>(avr, uart->r_udr, &on_udr_write, this);
        // UDRIE/TXEN live in UCSRnB: simavr's handler may raise UDRE there.
        control_hook_ = std::make_unique<IoWriteHook>(avr, static_cast<avr_io_addr_t>(uart->udrc.enable.reg),
                                                      &on_control_write, this);
        avr_irq_register_notify(uart->udrc.irq + AVR_INT_IRQ_PENDING, &on_udre_pending, this);
        original_reset_ = uart->io.reset;
        uart->io.reset = &on_reset;
        tx_registry().add(&uart->io, this);
        // simavr's reset sets TXEN ("allow printf without fiddling with enabling
        // the uart"); UCSRnB resets to 0 (328P §20.11.3).
        avr_regbit_clear(avr, uart->txen);
    }

    ~UartTransmitter() override {
        udr_hook_.reset();
        control_hook_.reset();
        avr_irq_unregister_notify(uart_->udrc.irq + AVR_INT_IRQ_PENDING, &on_udre_pending, this);
        avr_cycle_timer_cancel(avr_, &on_frame_end, this);
        uart_->io.reset = original_reset_;
        tx_registry().remove(&uart_->io);
    }

private:
    bool udre() const { return avr_regbit_get(avr_, uart_->udrc.raised) != 0; }

    void set_udre(bool empty) {
        avr_int_vector_t* v = &uart_->udrc;
        if (empty) {
            // A level interrupt: pending while UDRE and UDRIE are both one.
            if (!udre() || (!v->pending && avr_regbit_get(avr_, v->enable))) avr_raise_interrupt(avr_, v);
            avr_regbit_set(avr_, v->raised);
        } else {
            if (v->pending) unpend_interrupt(avr_, v);
            avr_regbit_clear(avr_, v->raised);
        }
    }

    void load(std::uint8_t byte, avr_cycle_count_t at) {
        shifting_ = true;
        shift_end_ = at + uart_->cycles_per_byte;
        // Observers stamp the byte with avr->cycle: present the start bit's
        // cycle (a timer runs after the instruction in progress, a few cycles late).
        const avr_cycle_count_t now = avr_->cycle;
        avr_->cycle = at;
        avr_raise_irq(uart_->io.irq + UART_IRQ_OUTPUT, byte);
        avr_->cycle = now;
    }

    static void on_udr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t, std::uint8_t value) {
        auto* self = static_cast<UartTransmitter*>(hook.context());
        avr_uart_t* u = self->uart_;
        // "The transmit buffer can only be written when the UDRE Flag is set."
        if (!avr_regbit_get(avr, u->txen) || self->buffered_) return;
        if (!self->shifting_) {
            self->load(value, avr->cycle);
            avr_cycle_timer_register(avr, u->cycles_per_byte, &on_frame_end, self);
            self->set_udre(true);
        } else {
            self->buffer_ = value;
            self->buffered_ = true;
            self->set_udre(false);
        }
    }

    static avr_cycle_count_t on_frame_end(avr_t* avr, avr_cycle_count_t when, void* param) {
        auto* self = static_cast<UartTransmitter*>(param);
        (void)avr;
        if (self->buffered_) {
            // The buffer moves to the shift register right after the stop bit.
            self->buffered_ = false;
            self->load(self->buffer_, when);
            self->set_udre(true);
            return self->shift_end_;
        }
        self->shifting_ = false;
        avr_raise_interrupt(self->avr_, &self->uart_->txc);  // TXC: frame out, buffer empty
        return 0;
    }

    // The UDRE interrupt was taken (simavr leaves the sticky flag set): it
    // asks again while UDRE and UDRIE stay one.
    static void on_udre_pending(avr_irq_t*, std::uint32_t value, void* param) {
        auto* self = static_cast<UartTransmitter*>(param);
        avr_int_vector_t* v = &self->uart_->udrc;
        if (value == 0 && self->udre() && avr_regbit_get(self->avr_, v->enable) && !v->pending) {
            avr_raise_interrupt(self->avr_, v);
        }
    }

    static void on_control_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<UartTransmitter*>(hook.context());
        hook.write_original(avr, addr, value);
        // simavr raises UDRE when UDRIE is enabled and its own (unused)
        // transmit timer is idle; the buffer decides.
        self->set_udre(!self->buffered_ && avr_regbit_get(avr, self->uart_->txen));
        if (!avr_regbit_get(avr, self->uart_->txen)) avr_regbit_set(avr, self->uart_->udrc.raised);
        sync_enables(avr, addr);
    }

    static void on_reset(avr_io_t* io) {
        UartTransmitter* self = tx_registry().find(io);
        self->original_reset_(io);
        avr_regbit_clear(self->avr_, self->uart_->txen);
        self->shifting_ = false;
        self->buffered_ = false;
    }

    avr_t* avr_;
    avr_uart_t* uart_;
    std::unique_ptr<IoWriteHook> udr_hook_, control_hook_;
    void (*original_reset_)(avr_io_t*) = nullptr;
    bool shifting_ = false;
    bool buffered_ = false;
    std::uint8_t buffer_ = 0;
    avr_cycle_count_t shift_end_ = 0;
};

class UartTransmitters final : public Fix {
public:
    std::vector<std::unique_ptr<UartTransmitter>> all;
};

}  // namespace

std::unique_ptr<Fix> install_uart_transmitter(avr_t* avr) {
    auto fix = std::make_unique<UartTransmitters>();
    for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind == nullptr || std::string_view(io->kind) != "uart") continue;
        auto* uart = reinterpret_cast<avr_uart_t*>(io);
        if (uart->udrc.vector == 0) continue;  // LIN mode UARTs
        fix->all.push_back(std::make_unique<UartTransmitter>(avr, uart));
    }
    return fix;
}

}  // namespace avrbench
