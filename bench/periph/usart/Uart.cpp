#include "periph/usart/Uart.hpp"

#include <algorithm>
#include <cstring>

extern "C" {
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_cycle_timers.h>
#include <sim_io.h>
}

#include "core/CycleAt.hpp"
#include "core/Errors.hpp"
#include "periph/ports/Pin.hpp"
#include "core/Scheduler.hpp"
#include "periph/Fixes.hpp"

namespace avrbench {

Uart::Uart(avr_t* avr, Scheduler& scheduler, int index, Pin* rx_pin)
    : avr_(avr), scheduler_(scheduler), index_(index), rx_pin_(rx_pin) {
    const char name = static_cast<char>('0' + index);
    for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind != nullptr && std::strcmp(io->kind, "uart") == 0 &&
            reinterpret_cast<avr_uart_t*>(io)->name == name) {
            uart_ = reinterpret_cast<avr_uart_t*>(io);
        }
    }
    if (uart_ == nullptr) {
        throw BadInput(std::string(avr->mmcu) + " has no USART" + std::to_string(index));
    }
    irqs_ = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ(name), 0);
    avr_irq_register_notify(irqs_ + UART_IRQ_OUTPUT, &Uart::on_output, this);
    avr_irq_register_notify(irqs_ + UART_IRQ_OUT_XON, &Uart::on_xon, this);
    avr_irq_register_notify(irqs_ + UART_IRQ_OUT_XOFF, &Uart::on_xoff, this);
}

Uart::~Uart() {
    avr_irq_unregister_notify(irqs_ + UART_IRQ_OUTPUT, &Uart::on_output, this);
    avr_irq_unregister_notify(irqs_ + UART_IRQ_OUT_XON, &Uart::on_xon, this);
    avr_irq_unregister_notify(irqs_ + UART_IRQ_OUT_XOFF, &Uart::on_xoff, this);
}

Cycle Uart::cycles_per_frame() const { return uart_->cycles_per_byte; }

void Uart::connect_host() {
    if (line_driver_ || rx_pin_ == nullptr || rx_from_line_ || rx_line_held_) return;
    rx_line_held_ = true;
    rx_pin_->drive(true);
}

void Uart::send(const std::string& bytes) {
    // A host with something to say is connected (if it did not say so before).
    if (!bytes.empty()) connect_host();
    to_send_.insert(to_send_.end(), bytes.begin(), bytes.end());
    pump();
}

void Uart::on_output(avr_irq_t* /*irq*/, std::uint32_t value, void* param) {
    auto* self = static_cast<Uart*>(param);
    const auto byte = static_cast<std::uint8_t>(value);
    const Cycle now = self->avr_->cycle;
    self->transmitted_.push_back({now, byte});
    for (auto& fn : self->tx_listeners_) fn(now, byte);
}

void Uart::on_xon(avr_irq_t* /*irq*/, std::uint32_t value, void* param) {
    auto* self = static_cast<Uart*>(param);
    if (value == 0) return;
    self->receiver_full_ = false;
    self->pump();
}

void Uart::on_xoff(avr_irq_t* /*irq*/, std::uint32_t value, void* param) {
    auto* self = static_cast<Uart*>(param);
    if (value != 0) self->receiver_full_ = true;
}

void Uart::pump() {
    if (pumping_) return;  // raising INPUT can re-enter through XON/XOFF
    pumping_ = true;
    while (!to_send_.empty() && !receiver_full_) {
        // simavr drops bytes that arrive while RXEN is clear; a host would be
        // lost the same way, but a bench that feeds a file wants every byte,
        // so hold them until the firmware opens its receiver.
        if (!avr_regbit_get(avr_, uart_->rxen)) break;
        const std::uint8_t byte = to_send_.front();
        to_send_.pop_front();
        draw_host_frame(byte);
        deliver(byte);
    }
    pumping_ = false;
    if (!to_send_.empty()) schedule_retry();
}

void Uart::deliver(std::uint16_t value) {
    ++delivered_;
    avr_raise_irq(irqs_ + UART_IRQ_INPUT, value);
    for (auto& fn : deliver_listeners_) fn(avr_->cycle, static_cast<std::uint8_t>(value));
}

void Uart::draw_host_frame(std::uint16_t value) {
    // simavr's FIFO sets RXC one frame after a byte enters it empty, then one
    // frame apart while it holds more: the frames sit end to end on the line.
    const UartFrame frame = uart_frame(avr_, uart_);
    const Cycle start = std::max<Cycle>(avr_->cycle, rx_line_free_at_);
    const Cycle frame_cycles = static_cast<Cycle>(frame.cycles_per_bit) * static_cast<Cycle>(frame.bits());
    rx_line_free_at_ = start + frame_cycles;
    if (line_driver_ || (rx_pin_ != nullptr && !rx_from_line_)) {
        const UartFrameLevels levels = uart_frame_levels(frame, value);
        bool level = true;  // the host holds the line idle high
        for (int i = 0; i < levels.count; ++i) {
            if (levels.high[static_cast<std::size_t>(i)] == level) continue;
            level = !level;
            scheduler_.at(start + static_cast<Cycle>(i) * frame.cycles_per_bit, [this, level](Cycle at) {
                CycleAt stamp(avr_, at);
                if (line_driver_) {
                    line_driver_(level);
                } else {
                    rx_pin_->drive(level);
                }
            });
        }
    }
    if (!rx_listeners_.empty()) {
        scheduler_.at(rx_line_free_at_, [this, value](Cycle at) {
            for (auto& fn : rx_listeners_) fn(at, static_cast<std::uint8_t>(value));
        });
    }
}

void Uart::listen_to_rx_line() {
    if (rx_from_line_ || rx_pin_ == nullptr) return;
    rx_from_line_ = true;
    if (rx_line_held_) rx_pin_->release();  // the board's net drives RxD now
    rx_pin_->on_change([this](Cycle cycle, bool high) { on_rx_edge(cycle, high); });
}

void Uart::host_drives_rx_line(std::function<void(bool high)> drive) {
    line_driver_ = std::move(drive);
    if (rx_line_held_ && rx_pin_ != nullptr) rx_pin_->release();
    rx_line_held_ = false;
}

void Uart::on_rx_edge(Cycle cycle, bool high) {
    if (line_driver_) return;  // the host's own frames: its bytes went to the receiver already
    if (line_frame_active_) {
        line_edges_.emplace_back(cycle, high);
        return;
    }
    // A falling edge on an idle line starts a frame (§20.8.1); the receiver
    // sees none while it is off.
    if (high || !avr_regbit_get(avr_, uart_->rxen)) return;
    const UartFrame frame = uart_frame(avr_, uart_);
    line_frame_active_ = true;
    line_frame_start_ = cycle;
    line_cycles_per_bit_ = frame.cycles_per_bit;
    line_edges_.clear();
    // The first stop bit's middle: bit index bits() - stop_bits, plus half a bit.
    const double stop_middle_bits = frame.bits() - frame.stop_bits + 0.5;
    scheduler_.at(cycle + static_cast<Cycle>(stop_middle_bits * frame.cycles_per_bit), [this](Cycle at) {
        CycleAt stamp(avr_, at);
        finish_line_frame();
    });
}

void Uart::finish_line_frame() {
    line_frame_active_ = false;
    const UartFrame frame = uart_frame(avr_, uart_);
    // The line's level in the middle of bit `index` (the start bit is index 0).
    auto level_at_bit = [this](int index) {
        const Cycle middle = line_frame_start_ + static_cast<Cycle>((index + 0.5) * line_cycles_per_bit_);
        bool high = false;
        for (const auto& [cycle, level] : line_edges_) {
            if (cycle > middle) break;
            high = level;
        }
        return high;
    };
    std::uint32_t data = 0;
    for (int i = 0; i < frame.data_bits; ++i) {
        if (level_at_bit(1 + i)) data |= 1u << i;
    }
    const UartFrameLevels expected = uart_frame_levels(frame, data);
    int index = 1 + frame.data_bits;
    if (frame.parity != 0) {
        if (level_at_bit(index) != expected.high[static_cast<std::size_t>(index)]) ++line_parity_errors_;
        ++index;
    }
    if (!level_at_bit(index)) ++line_framing_errors_;
    // The rest of the frame's edges belong to no one: a falling edge after the
    // stop bit's middle is the next start bit.
    bool next_start = false;
    Cycle next_start_cycle = 0;
    const Cycle stop_middle = line_frame_start_ + static_cast<Cycle>((index + 0.5) * line_cycles_per_bit_);
    for (const auto& [cycle, level] : line_edges_) {
        if (cycle > stop_middle && !level) {
            next_start = true;
            next_start_cycle = cycle;
        }
    }

    if (avr_regbit_get(avr_, uart_->rxen)) {
        // simavr starts its receive-complete timer a whole frame after a byte
        // enters an empty FIFO; the frame is over on the line already, so the
        // timer is brought forward to now.
        const bool fifo_was_idle = rxc_timer_ == nullptr || avr_cycle_timer_status(avr_, rxc_timer_, uart_) == 0;
        std::vector<avr_cycle_timer_t> before;
        if (rxc_timer_ == nullptr) {
            for (avr_cycle_timer_slot_p t = avr_->cycle_timers.timer; t != nullptr; t = t->next) {
                if (t->param == uart_) before.push_back(t->timer);
            }
        }
        deliver(static_cast<std::uint16_t>(data));
        if (rxc_timer_ == nullptr) {
            for (avr_cycle_timer_slot_p t = avr_->cycle_timers.timer; t != nullptr; t = t->next) {
                if (t->param == uart_ && std::find(before.begin(), before.end(), t->timer) == before.end()) {
                    rxc_timer_ = t->timer;
                }
            }
        }
        if (fifo_was_idle && rxc_timer_ != nullptr && avr_cycle_timer_status(avr_, rxc_timer_, uart_) != 0) {
            avr_cycle_timer_cancel(avr_, rxc_timer_, uart_);
            avr_cycle_timer_register(avr_, 0, rxc_timer_, uart_);
        }
        for (auto& fn : rx_listeners_) fn(avr_->cycle, static_cast<std::uint8_t>(data));
    }
    if (next_start) {
        std::vector<std::pair<Cycle, bool>> rest;
        for (const auto& e : line_edges_) {
            if (e.first > next_start_cycle) rest.push_back(e);
        }
        on_rx_edge(next_start_cycle, false);
        for (const auto& [cycle, level] : rest) on_rx_edge(cycle, level);
    }
}

void Uart::schedule_retry() {
    if (retry_scheduled_) return;
    retry_scheduled_ = true;
    // Poll at one frame time: cheap, and no slower than the line itself.
    const Cycle frame = uart_->cycles_per_byte > 0 ? uart_->cycles_per_byte : 1000;
    scheduler_.after(frame, [this](Cycle) {
        retry_scheduled_ = false;
        pump();
    });
}

}  // namespace avrbench
