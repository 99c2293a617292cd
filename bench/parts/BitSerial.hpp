// Asynchronous serial frames on two pins of a part, at the pin level: 8 data
// bits, no parity, 1 stop bit, LSB first, idle high (the frame of ATmega328P
// §20.4, which SoftwareSerial imitates). The encoder puts a frame's bit levels
// on the TX pin at the bit grid of `baud`; the decoder starts a frame at a
// falling edge on an idle RX line and samples the middle of each bit, as a
// receiver does (§20.8). Shared by the parts that talk serial on pins
// (serial_peer, a serial_host on bit-banged pins).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <string>

#include "mcu/Mcu.hpp"
#include "core/Time.hpp"

namespace avrbench {

class BitSerial {
public:
    struct Hooks {
        std::function<void(bool high)> drive_tx;
        std::function<bool()> rx_level;
        // A frame read whole: its start bit's cycle and its data.
        std::function<void(Cycle frame_start, std::uint8_t byte)> on_byte;
        // A frame whose stop bit read 0 (the byte is dropped).
        std::function<void(Cycle frame_start)> on_framing_error;
        // An edge inside a frame, `bits` after its start bit's edge (on the
        // grid when a whole number); optional.
        std::function<void(double bits)> on_edge;
        // A frame sent whole: its stop bit begins now (the receiver has its
        // data bits); optional.
        std::function<void(Cycle stop_bit, std::uint8_t byte)> on_sent;
    };

    BitSerial(Mcu& clock, double baud, Hooks hooks);

    // Queues `bytes`, the first start bit at `at_cycle` or when the line is
    // free, the others frame after frame. Streamed: one bit's event is
    // scheduled at a time, so a long queue costs its bytes and no more.
    void send(const std::string& bytes, Cycle at_cycle);
    // Bytes queued and not yet sent whole.
    std::uint64_t bytes_queued() const { return queued_; }
    std::uint64_t bytes_sent() const { return sent_; }
    // The RX pin changed level (call from the part's on_input).
    void rx_edge(bool level);

    double bit_cycles() const { return bit_cycles_; }
    Cycle frame_cycles() const { return bit_time(0, 10.0); }
    // When the last queued frame's stop bit ends.
    Cycle tx_free_at() const { return tx_free_at_; }

private:
    Cycle bit_time(Cycle frame_start, double bits) const;
    void sample(unsigned bit_index);
    void transmit_bit();  // the bit at tx_bit_ of the frame at tx_frame_start_
    void schedule_transmit(Cycle at);

    // Queued text in chunks as send() got it, each with its first frame's start.
    struct Chunk {
        std::string bytes;
        Cycle first_start = 0;
    };
    std::deque<Chunk> tx_chunks_;
    std::size_t tx_index_ = 0;   // the byte of the front chunk on the line
    unsigned tx_bit_ = 0;        // 0 start bit, 1..8 data, 9 stop
    Cycle tx_frame_start_ = 0;
    bool tx_active_ = false;
    std::uint64_t queued_ = 0, sent_ = 0;

    Mcu& clock_;
    double bit_cycles_;
    Hooks hooks_;
    bool receiving_ = false;
    Cycle frame_start_ = 0;
    unsigned shift_ = 0;
    Cycle tx_free_at_ = 0;
};

}  // namespace avrbench
