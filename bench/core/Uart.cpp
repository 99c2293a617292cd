#include "core/Uart.hpp"

#include <cstring>

extern "C" {
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_io.h>
}

#include "core/Errors.hpp"
#include "core/Scheduler.hpp"

namespace avrbench {

Uart::Uart(avr_t* avr, Scheduler& scheduler, int index) : avr_(avr), scheduler_(scheduler), index_(index) {
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

std::string Uart::transmitted_text() const {
    std::string out;
    out.reserve(transmitted_.size());
    for (const auto& b : transmitted_) out.push_back(static_cast<char>(b.value));
    return out;
}

Cycle Uart::cycles_per_frame() const { return uart_->cycles_per_byte; }

void Uart::send(const std::string& bytes) {
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
        ++delivered_;
        avr_raise_irq(irqs_ + UART_IRQ_INPUT, byte);
    }
    pumping_ = false;
    if (!to_send_.empty()) schedule_retry();
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
