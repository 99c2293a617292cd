// One USART of an MCU seen from the outside: the bytes the firmware sends
// (each with the cycle of its start bit: fixes/UartTransmitter) and a queue of bytes to send it,
// paced by simavr's receive FIFO (XON/XOFF IRQs) and held back until the
// firmware has enabled its receiver, as a host would wait for the port.
//
// The RxDn pin (ATmega328P §20.7, Table 14-9). From the first byte a host
// queues, the pin idles high (the host's TX is connected); its bytes are drawn
// on it as frames (start bit low, data LSB first, parity, stop bits high) at
// the USART's bit time, one frame after the other from the moment each byte
// enters simavr's receive FIFO, whose receive-complete flag follows one frame
// later (so the firmware has the byte when its frame has ended on the pin).
// Where a board wires RxDn to a net (a serial_peer, another MCU's TXD), the
// net drives the pin and the USART receives what it carries instead
// (listen_to_rx_line): a falling edge while idle starts a frame, each bit is
// read in its middle (§20.8 samples bits 8, 9, 10 of 16 and votes), and the
// byte reaches the receiver at the middle of its first stop bit with RXC set
// then (§20.7.1).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "core/SerialLink.hpp"
#include "core/Time.hpp"

struct avr_t;
struct avr_irq_t;
struct avr_uart_t;

namespace avrbench {

class Pin;
class Scheduler;

class Uart final : public SerialLink {
public:
    using TxListener = ByteListener;

    // Throws BadInput if the MCU has no USART `index`. `rx_pin` is its RxDn
    // pin, nullptr where the bench does not know the pin-out.
    Uart(avr_t* avr, Scheduler& scheduler, int index, Pin* rx_pin = nullptr);
    Uart(const Uart&) = delete;
    Uart& operator=(const Uart&) = delete;
    ~Uart();

    int index() const { return index_; }

    // Bytes the firmware transmitted, in order.
    const std::vector<UartByte>& transmitted() const override { return transmitted_; }
    void on_transmit(TxListener fn) override { tx_listeners_.push_back(std::move(fn)); }

    // A host is connected to RxD from now on: its TX idles high, so a logic
    // analyser sees each start bit as a falling edge (send() does this too).
    // Nothing when a board's net drives RxD.
    void connect_host() override;
    // Queues bytes for the firmware's receiver.
    void send(const std::string& bytes) override;
    // Bytes the receiver took (from a host or from the RxDn line), each with
    // the cycle its receive-complete flag was set.
    void on_receive(TxListener fn) { rx_listeners_.push_back(std::move(fn)); }
    // The board drives RxDn through a net: receive the frames on the pin
    // (host bytes still go straight to the receiver, not drawn on the pin).
    void listen_to_rx_line();
    // A host on the board's RxDn net draws the frames of the bytes sent
    // through this USART with `drive` (its TX pin), at the same cycles the
    // pin would show them; the receiver gets the bytes straight, so the line
    // is no longer decoded. The byte-level attachment of a serial_host part.
    void host_drives_rx_line(std::function<void(bool high)> drive);
    // Frames read from the line whose stop bit was low, or whose parity bit
    // did not match (§20.7.4, FEn and UPEn; the byte is delivered anyway).
    std::uint64_t line_framing_errors() const { return line_framing_errors_; }
    std::uint64_t line_parity_errors() const { return line_parity_errors_; }
    std::size_t pending_rx() const override { return to_send_.size(); }
    std::uint64_t bytes_delivered() const override { return delivered_; }
    void on_deliver(ByteListener fn) override { deliver_listeners_.push_back(std::move(fn)); }

    // Datasheet frame time for the current UBRR/U2X/UCSZ settings.
    Cycle cycles_per_frame() const override;

private:
    static void on_output(avr_irq_t* irq, std::uint32_t value, void* param);
    static void on_xon(avr_irq_t* irq, std::uint32_t value, void* param);
    static void on_xoff(avr_irq_t* irq, std::uint32_t value, void* param);
    void pump();
    void schedule_retry();
    // Puts `byte` into simavr's receive FIFO.
    void deliver(std::uint16_t value);
    // Draws a host byte's frame on RxDn and reports it when the receiver has it.
    void draw_host_frame(std::uint16_t value);
    void on_rx_edge(Cycle cycle, bool high);
    void finish_line_frame();

    avr_t* avr_;
    Scheduler& scheduler_;
    int index_;
    avr_uart_t* uart_ = nullptr;
    avr_irq_t* irqs_ = nullptr;
    std::vector<UartByte> transmitted_;
    std::vector<TxListener> tx_listeners_;
    std::deque<std::uint8_t> to_send_;
    std::vector<ByteListener> deliver_listeners_;
    std::uint64_t delivered_ = 0;
    bool receiver_full_ = false;
    bool retry_scheduled_ = false;
    bool pumping_ = false;
    std::vector<TxListener> rx_listeners_;

    Pin* rx_pin_;
    std::function<void(bool high)> line_driver_;
    Cycle rx_line_free_at_ = 0;  // the end of the last host frame drawn on RxDn
    bool rx_from_line_ = false;
    bool rx_line_held_ = false;  // RxD driven idle high since the first host byte was queued
    // The frame being read from the line: its start bit's cycle and the edges since.
    bool line_frame_active_ = false;
    Cycle line_frame_start_ = 0;
    std::uint32_t line_cycles_per_bit_ = 0;
    std::vector<std::pair<Cycle, bool>> line_edges_;
    std::uint64_t line_framing_errors_ = 0;
    std::uint64_t line_parity_errors_ = 0;
    // simavr's receive-complete timer (learnt from the first delivery into an
    // empty FIFO), moved up to the middle of the stop bit for line frames.
    std::uint64_t (*rxc_timer_)(avr_t*, std::uint64_t, void*) = nullptr;
};

}  // namespace avrbench
