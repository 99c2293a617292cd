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
//
// The TxDn pin (§20.6.1, Table 14-9: DDOE = PVOE = TXEN, DDOV = 1): while the
// transmitter is enabled the USART drives it as an output, idle high, and
// each frame goes out bit by bit - start bit low, 5 to 9 data bits LSB first
// (the ninth from TXB8), the parity bit (even or odd over the data bits),
// one or two stop bits high - each bit cycles_per_bit long from the start
// bit's cycle, edges at exact cycles (the timer that raises them presents
// its own cycle). TXEN cleared takes effect once the frames queued are out
// (§20.6.5 "Disabling the Transmitter").
#include <string_view>
#include <vector>

extern "C" {
#include <avr_uart.h>
#include <sim_cycle_timers.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include <deque>

#include "core/CycleAt.hpp"
#include "periph/ports/McuPins.hpp"
#include "periph/timer/CompareOutputPins.hpp"
#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {
namespace {

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
        FixState<UartTransmitter>::add(&uart->io, this);
        // simavr's reset sets TXEN ("allow printf without fiddling with enabling
        // the uart"); UCSRnB resets to 0 (328P §20.11.3).
        avr_regbit_clear(avr, uart->txen);
        // The TxDn pin, where the bench knows the part's pin-out.
        if (auto pins = usart_pins(avr->mmcu != nullptr ? avr->mmcu : "", uart->name - '0'); pins && CompareOutputPins::of(avr)) {
            pins_ = CompareOutputPins::of(avr);
            tx_driver_ = pins_->add_forced_output(pins->tx_port, pins->tx_bit);
        }
    }

    ~UartTransmitter() override {
        udr_hook_.reset();
        control_hook_.reset();
        avr_irq_unregister_notify(uart_->udrc.irq + AVR_INT_IRQ_PENDING, &on_udre_pending, this);
        avr_cycle_timer_cancel(avr_, &on_frame_end, this);
        avr_cycle_timer_cancel(avr_, &on_line_edge, this);
        uart_->io.reset = original_reset_;
        FixState<UartTransmitter>::remove(&uart_->io);
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
        queue_frame(byte, at);
        // Observers stamp the byte with avr->cycle: present the start bit's
        // cycle (a timer runs after the instruction in progress, a few cycles late).
        CycleAt stamp(avr_, at);
        avr_raise_irq(uart_->io.irq + UART_IRQ_OUTPUT, byte);
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
        self->drive_line();
    }

    static void on_reset(avr_io_t* io) {
        UartTransmitter* self = FixState<UartTransmitter>::find(io);
        self->original_reset_(io);
        avr_regbit_clear(self->avr_, self->uart_->txen);
        self->shifting_ = false;
        self->buffered_ = false;
        self->edges_.clear();
        avr_cycle_timer_cancel(self->avr_, &on_line_edge, self);
        self->line_high_ = true;
        self->drive_line();
    }

    // --- the TxDn pin -----------------------------------------------------

    // The frame's level changes, from the start bit at `at`.
    void queue_frame(std::uint8_t byte, avr_cycle_count_t at) {
        if (tx_driver_ < 0) return;
        const UartFrame f = uart_frame(avr_, uart_);
        std::uint32_t data = byte;
        if (f.data_bits == 9 && (avr_->data[uart_->r_ucsrb] & 0x01) != 0) data |= 0x100;  // TXB8n (§20.11.3)
        const UartFrameLevels levels = uart_frame_levels(f, data);
        bool level = edges_.empty() ? line_high_ : edges_.back().high;
        for (int i = 0; i < levels.count; ++i) {
            if (levels.high[static_cast<std::size_t>(i)] == level) continue;
            level = !level;
            edges_.push_back({at + static_cast<avr_cycle_count_t>(i) * f.cycles_per_bit, level});
        }
        if (!edges_.empty() && avr_cycle_timer_status(avr_, &on_line_edge, this) == 0) {
            avr_cycle_timer_register(avr_, edges_.front().at > avr_->cycle ? edges_.front().at - avr_->cycle : 0,
                                     &on_line_edge, this);
        }
    }

    static avr_cycle_count_t on_line_edge(avr_t* avr, avr_cycle_count_t when, void* param) {
        auto* self = static_cast<UartTransmitter*>(param);
        while (!self->edges_.empty() && self->edges_.front().at <= when) {
            const Edge e = self->edges_.front();
            self->edges_.pop_front();
            self->line_high_ = e.high;
            CycleAt stamp(avr, e.at);  // listeners stamp the edge with the bit's own cycle
            self->drive_line();
        }
        if (self->edges_.empty()) {
            self->drive_line();  // TXEN cleared while frames were queued: let go now
            return 0;
        }
        return self->edges_.front().at;
    }

    // The pin: driven while TXEN is set or a frame is still going out.
    void drive_line() {
        if (tx_driver_ < 0) return;
        const bool connected = avr_regbit_get(avr_, uart_->txen) != 0 || !edges_.empty();
        pins_->set(tx_driver_, connected, line_high_);
    }

    avr_t* avr_;
    avr_uart_t* uart_;
    std::unique_ptr<IoWriteHook> udr_hook_, control_hook_;
    void (*original_reset_)(avr_io_t*) = nullptr;
    bool shifting_ = false;
    bool buffered_ = false;
    std::uint8_t buffer_ = 0;
    avr_cycle_count_t shift_end_ = 0;

    struct Edge {
        avr_cycle_count_t at;
        bool high;
    };
    CompareOutputPins* pins_ = nullptr;
    int tx_driver_ = -1;     // TxDn's driver, -1 when the pin-out is unknown
    bool line_high_ = true;  // the line now: idle high
    std::deque<Edge> edges_; // level changes of the frames going out, in order
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
