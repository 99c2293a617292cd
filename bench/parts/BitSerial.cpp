#include "parts/BitSerial.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/Scheduler.hpp"

namespace avrbench {

BitSerial::BitSerial(Mcu& clock, double baud, Hooks hooks)
    : clock_(clock), bit_cycles_(clock.frequency_hz() / baud), hooks_(std::move(hooks)) {}

Cycle BitSerial::bit_time(Cycle frame_start, double bits) const {
    return frame_start + static_cast<Cycle>(std::llround(bits * bit_cycles_));
}

void BitSerial::send(const std::string& bytes, Cycle at_cycle) {
    Cycle start = std::max({at_cycle, tx_free_at_, clock_.cycle()});
    for (unsigned char byte : bytes) {
        // start bit 0, 8 data bits LSB first, stop bit 1
        std::vector<bool> bits{false};
        for (int i = 0; i < 8; ++i) bits.push_back(((byte >> i) & 1) != 0);
        bits.push_back(true);
        for (std::size_t i = 0; i < bits.size(); ++i) {
            const bool level = bits[i];
            clock_.scheduler().at(bit_time(start, static_cast<double>(i)), [this, level](Cycle) { hooks_.drive_tx(level); });
        }
        start = bit_time(start, 10.0);
    }
    tx_free_at_ = start;
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
