// A binary stop-and-wait host on a UART (seed 002's PC program): sends one
// message, waits for the firmware's ACK byte, sends the next. A NAK, any
// other byte, or no ACK within the timeout (simulated time) stops it with a
// failure that names the message; it never waits forever.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mcu/Mcu.hpp"
#include "core/SerialLink.hpp"

namespace avrbench {

class RecordHost {
public:
    struct Options {
        std::uint8_t ack = 0x06;
        std::uint8_t nak = 0x15;
        double ack_timeout_s = 5.0;
    };

    // `busy_seconds` (optional, one per message): how long the firmware works
    // on a message before its ACK is due; added to the timeout.
    RecordHost(Mcu& mcu, SerialLink& uart, std::vector<std::string> messages, Options options,
               std::vector<double> busy_seconds = {});
    RecordHost(const RecordHost&) = delete;
    RecordHost& operator=(const RecordHost&) = delete;

    void start();  // sends the first message
    std::size_t messages() const { return messages_.size(); }
    std::size_t acknowledged() const { return acked_; }
    bool finished() const { return acked_ == messages_.size(); }
    bool failed() const { return !failure_.empty(); }
    const std::string& failure() const { return failure_; }
    Cycle failure_cycle() const { return failure_cycle_; }

private:
    void on_byte(Cycle cycle, std::uint8_t byte);
    void send_next();
    void fail(Cycle cycle, std::string why);

    Mcu& mcu_;
    SerialLink& uart_;
    std::vector<std::string> messages_;
    Options options_;
    std::vector<double> busy_seconds_;
    std::size_t sent_ = 0, acked_ = 0;
    std::string failure_;
    Cycle failure_cycle_ = 0;
};

}  // namespace avrbench
