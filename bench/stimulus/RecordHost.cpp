#include "stimulus/RecordHost.hpp"

#include <cstdio>

namespace avrbench {

RecordHost::RecordHost(Mcu& mcu, SerialLink& uart, std::vector<std::string> messages, Options options,
                       std::vector<double> busy_seconds)
    : mcu_(mcu), uart_(uart), messages_(std::move(messages)), options_(options), busy_seconds_(std::move(busy_seconds)) {
    uart_.on_transmit([this](Cycle cycle, std::uint8_t byte) { on_byte(cycle, byte); });
}

void RecordHost::start() {
    if (sent_ == 0 && !messages_.empty()) send_next();
}

void RecordHost::send_next() {
    const std::size_t index = sent_++;
    uart_.send(messages_[index]);
    // A message waits for the one before it to finish (arc records are taken while a chord runs).
    double busy_s = index < busy_seconds_.size() ? busy_seconds_[index] : 0.0;
    if (index > 0 && index - 1 < busy_seconds_.size()) busy_s += busy_seconds_[index - 1];
    const Cycle deadline = mcu_.cycle() + mcu_.cycles_from_seconds(options_.ack_timeout_s + busy_s);
    mcu_.scheduler().at(deadline, [this, index, busy_s](Cycle now) {
        if (acked_ <= index && !failed()) {
            char why[160];
            std::snprintf(why, sizeof why, "no ACK for message %zu of %zu (first byte 0x%02X) within %g s of sending it",
                          index + 1, messages_.size(), static_cast<unsigned char>(messages_[index][0]),
                          options_.ack_timeout_s + busy_s);
            fail(now, why);
        }
    });
}

void RecordHost::fail(Cycle cycle, std::string why) {
    failure_ = std::move(why);
    failure_cycle_ = cycle;
}

void RecordHost::on_byte(Cycle cycle, std::uint8_t byte) {
    if (failed()) return;
    char why[160];
    if (byte == options_.ack) {
        if (acked_ >= sent_) {
            std::snprintf(why, sizeof why, "an ACK with no message waiting for one (after %zu)", acked_);
            fail(cycle, why);
            return;
        }
        ++acked_;
        if (sent_ < messages_.size()) send_next();
        return;
    }
    if (byte == options_.nak) {
        std::snprintf(why, sizeof why, "NAK for message %zu of %zu (first byte 0x%02X)", sent_, messages_.size(),
                      static_cast<unsigned char>(messages_[sent_ - 1][0]));
    } else {
        std::snprintf(why, sizeof why, "byte 0x%02X where an ACK was expected (message %zu)", byte, sent_);
    }
    fail(cycle, why);
}

}  // namespace avrbench
