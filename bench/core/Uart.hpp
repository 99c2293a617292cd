// One USART of an MCU seen from the outside: the bytes the firmware sends
// (each with the cycle of its start bit: fixes/UartTransmitter) and a queue of bytes to send it,
// paced by simavr's receive FIFO (XON/XOFF IRQs) and held back until the
// firmware has enabled its receiver, as a host would wait for the port.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "core/Time.hpp"

struct avr_t;
struct avr_irq_t;
struct avr_uart_t;

namespace avrbench {

class Scheduler;

struct UartByte {
    Cycle cycle;
    std::uint8_t value;
};

class Uart {
public:
    using TxListener = std::function<void(Cycle cycle, std::uint8_t byte)>;

    // Throws BadInput if the MCU has no USART `index`.
    Uart(avr_t* avr, Scheduler& scheduler, int index);
    Uart(const Uart&) = delete;
    Uart& operator=(const Uart&) = delete;
    ~Uart();

    int index() const { return index_; }

    // Bytes the firmware transmitted, in order.
    const std::vector<UartByte>& transmitted() const { return transmitted_; }
    std::string transmitted_text() const;
    void on_transmit(TxListener fn) { tx_listeners_.push_back(std::move(fn)); }

    // Queues bytes for the firmware's receiver.
    void send(const std::string& bytes);
    std::size_t pending_rx() const { return to_send_.size(); }
    std::uint64_t bytes_delivered() const { return delivered_; }

    // Datasheet frame time for the current UBRR/U2X/UCSZ settings.
    Cycle cycles_per_frame() const;

private:
    static void on_output(avr_irq_t* irq, std::uint32_t value, void* param);
    static void on_xon(avr_irq_t* irq, std::uint32_t value, void* param);
    static void on_xoff(avr_irq_t* irq, std::uint32_t value, void* param);
    void pump();
    void schedule_retry();

    avr_t* avr_;
    Scheduler& scheduler_;
    int index_;
    avr_uart_t* uart_ = nullptr;
    avr_irq_t* irqs_ = nullptr;
    std::vector<UartByte> transmitted_;
    std::vector<TxListener> tx_listeners_;
    std::deque<std::uint8_t> to_send_;
    std::uint64_t delivered_ = 0;
    bool receiver_full_ = false;
    bool retry_scheduled_ = false;
    bool pumping_ = false;
};

}  // namespace avrbench
