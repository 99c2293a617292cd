// A serial line seen from the host's end, byte by byte: what a G-code
// sender, a pty bridge or a file of raw bytes needs, whatever carries the
// bytes. A USART's hardware (periph/usart/Uart) is one; a host on two GPIO pins that
// the firmware bit-bangs (parts/SerialHost) is another.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/Time.hpp"

namespace avrbench {

struct UartByte {
    Cycle cycle;
    std::uint8_t value;
};

class SerialLink {
public:
    using ByteListener = std::function<void(Cycle cycle, std::uint8_t byte)>;
    virtual ~SerialLink() = default;

    // Bytes the firmware transmitted, in order, each with its start bit's cycle.
    virtual const std::vector<UartByte>& transmitted() const = 0;
    std::string transmitted_text() const;
    virtual void on_transmit(ByteListener fn) = 0;

    // A host is on the line from now on: its TX idles high.
    virtual void connect_host() = 0;
    // Queues bytes for the firmware, sent one frame after the other.
    virtual void send(const std::string& bytes) = 0;
    // Bytes handed to the firmware's side of the line so far.
    virtual std::uint64_t bytes_delivered() const = 0;
    // Called as each byte reaches the firmware's side (its cycle, the byte).
    virtual void on_deliver(ByteListener fn) = 0;
    // Bytes queued and not yet on their way.
    virtual std::size_t pending_rx() const = 0;
    // One frame's length on the line now, in the link's clock cycles.
    virtual Cycle cycles_per_frame() const = 0;
};

}  // namespace avrbench
