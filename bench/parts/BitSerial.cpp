#include "parts/BitSerial.hpp"

#include <algorithm>
#include <cmath>

#include "core/Scheduler.hpp"

namespace avrbench {

BitSerial::BitSerial(Mcu& clock, double baud, Hooks hooks)
    : clock_(clock), bit_cycles_(clock.frequency_hz() / baud), hooks_(std::move(hooks)) {}

Cycle BitSerial::bit_time(Cycle frame_start, double bits) const {
    return frame_start + static_cast<Cycle>(std::llround(bits * bit_cycles_));
}

void BitSerial::send(const std::string& bytes, Cycle at_cycle) {
    if (bytes.empty()) return;
    // Frames sit end to end: the first at `at_cycle` or when the line is free.
    const Cycle start = std::max({at_cycle, tx_free_at_, clock_.cycle()});
    Cycle end = start;
    for (std::size_t i = 0; i < bytes.size(); ++i) end = bit_time(end, 10.0);
    tx_free_at_ = end;
    queued_ += bytes.size();
    tx_chunks_.push_back({bytes, start});
    if (!tx_active_) {
        tx_active_ = true;
        tx_index_ = 0;
        tx_bit_ = 0;
        tx_frame_start_ = start;
        schedule_transmit(start);
    }
}

void BitSerial::schedule_transmit(Cycle at) {
    clock_.scheduler().at(at, [this](Cycle) { transmit_bit(); });
}

// start bit 0, 8 data bits LSB first, stop bit 1
void BitSerial::transmit_bit() {
    const auto byte = static_cast<std::uint8_t>(tx_chunks_.front().bytes[tx_index_]);
    const bool level = tx_bit_ == 0 ? false : tx_bit_ == 9 ? true : ((byte >> (tx_bit_ - 1)) & 1) != 0;
    hooks_.drive_tx(level);
    if (tx_bit_ < 9) {
        ++tx_bit_;
        schedule_transmit(bit_time(tx_frame_start_, static_cast<double>(tx_bit_)));
        return;
    }
    ++sent_;
    if (hooks_.on_sent) hooks_.on_sent(clock_.cycle(), byte);
    // The next frame: right after this one, or a later chunk's own start.
    tx_frame_start_ = bit_time(tx_frame_start_, 10.0);
    tx_bit_ = 0;
    if (++tx_index_ == tx_chunks_.front().bytes.size()) {
        tx_chunks_.pop_front();
        tx_index_ = 0;
        if (tx_chunks_.empty()) {
            tx_active_ = false;
            return;
        }
        tx_frame_start_ = std::max(tx_frame_start_, tx_chunks_.front().first_start);
    }
    schedule_transmit(tx_frame_start_);
}

void BitSerial::rx_edge(bool level) {
    const Cycle now = clock_.cycle();
    if (!receiving_) {
        if (level) return;
        receiving_ = true;
        frame_start_ = now;
        shift_ = 0;
        clock_.scheduler().at(bit_time(frame_start_, 0.5), [this](Cycle) { sample(0); });
        return;
    }
    if (hooks_.on_edge) hooks_.on_edge(static_cast<double>(now - frame_start_) / bit_cycles_);
}

// bit_index 0 = start bit, 1..8 data, 9 stop.
void BitSerial::sample(unsigned bit_index) {
    const bool level = hooks_.rx_level();
    if (bit_index == 0 && level) {  // a glitch, not a start bit
        receiving_ = false;
        return;
    }
    if (bit_index >= 1 && bit_index <= 8 && level) shift_ |= 1u << (bit_index - 1);
    if (bit_index == 9) {
        receiving_ = false;
        if (!level) {
            if (hooks_.on_framing_error) hooks_.on_framing_error(frame_start_);
            return;
        }
        hooks_.on_byte(frame_start_, static_cast<std::uint8_t>(shift_));
        return;
    }
    clock_.scheduler().at(bit_time(frame_start_, bit_index + 1.5), [this, bit_index](Cycle) { sample(bit_index + 1); });
}

}  // namespace avrbench
