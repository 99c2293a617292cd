#include "parts/SerialPeer.hpp"

#include "parts/PartRegistry.hpp"

#include <cmath>
#include <cstdio>

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(SerialPeer, "serial_peer");

const FindingKind SerialPeer::kSerialFraming = FindingKind::declare("serial-framing", "a pin-level serial frame with a bad stop bit or edges off the bit grid", Severity::Warning);

std::vector<ParamSpec> SerialPeer::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "baud", .type = PT::Quantity, .default_value = "9600",
         .source = "SoftwareSerial examples: 9600 baud", .help = "bits per second", .min = 50, .max = 2e6},
        {.name = "tolerance", .type = PT::Quantity, .default_value = "0.05",
         .source = "ATmega328P §20.8 Table 20-2: 8N1 receiver error budget about +-4.5 %",
         .help = "edge error allowed, in bits", .min = 1e-6, .max = 0.499},
        {.name = "send", .type = PT::Text, .help = "bytes to send once the board starts"},
        {.name = "send_at", .type = PT::Quantity, .dimension = D::Time, .default_value = "10ms",
         .source = "assumed: after the sketch's setup()", .help = "when to start sending `send`"},
    };
}

SerialPeer::SerialPeer(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      baud_(params.quantity("baud")),
      tolerance_bits_(params.quantity("tolerance")),
      send_at_start_(params.has("send") ? params.text("send") : std::string()),
      send_at_s_(params.quantity("send_at")) {
    // 50 baud (teleprinters) to 2 Mbaud (the fastest USART setting at 16 MHz, U2X: §20.3.1).
    if (!(baud_ >= 50 && baud_ <= 2e6)) throw BadInput("part '" + this->name() + "': baud must be from 50 to 2000000");
    if (!(tolerance_bits_ > 0 && tolerance_bits_ < 0.5)) {
        throw BadInput("part '" + this->name() + "': tolerance must be more than 0 and less than half a bit");
    }
    if (!(send_at_s_ >= 0 && send_at_s_ <= 1e6)) throw BadInput("part '" + this->name() + "': send_at must be from 0 to 1e6 s");
    bit_cycles_ = clock.frequency_hz() / baud_;
    rx_pin_ = add_pin("rx", TerminalRole::Input);
    tx_pin_ = add_pin("tx", TerminalRole::Output);
}

void SerialPeer::start() {
    drive_output(tx_pin_, true);  // idle: mark
    if (!send_at_start_.empty()) send(send_at_start_, clock().cycles_from_seconds(send_at_s_));
}

Cycle SerialPeer::bit_time(Cycle frame_start, double bits) const {
    return frame_start + static_cast<Cycle>(std::llround(bits * bit_cycles_));
}

void SerialPeer::send(const std::string& bytes, Cycle at_cycle) {
    Cycle start = std::max({at_cycle, tx_free_at_, clock().cycle()});
    for (unsigned char byte : bytes) {
        // start bit 0, 8 data bits LSB first, stop bit 1
        std::vector<bool> bits{false};
        for (int i = 0; i < 8; ++i) bits.push_back(((byte >> i) & 1) != 0);
        bits.push_back(true);
        for (std::size_t i = 0; i < bits.size(); ++i) {
            const bool level = bits[i];
            clock().scheduler().at(bit_time(start, static_cast<double>(i)), [this, level](Cycle) { drive_output(tx_pin_, level); });
        }
        start = bit_time(start, 10.0);
    }
    tx_free_at_ = start;
}

void SerialPeer::on_input(std::size_t pin, bool level) {
    if (pin != rx_pin_) return;
    const Cycle now = clock().cycle();
    if (!receiving_) {
        if (level) return;
        receiving_ = true;
        frame_start_ = now;
        shift_ = 0;
        clock().scheduler().at(bit_time(frame_start_, 0.5), [this](Cycle) { sample(0); });
        return;
    }
    // An edge inside a frame belongs on a bit boundary.
    const double bits = static_cast<double>(now - frame_start_) / bit_cycles_;
    worst_edge_error_bits_ = std::max(worst_edge_error_bits_, std::fabs(bits - std::round(bits)));
    if (std::fabs(bits - std::round(bits)) > tolerance_bits_) {
        char detail[128];
        std::snprintf(detail, sizeof detail, "edge %.3f bits into a frame: off the %g-baud bit grid by more than %g bit",
                      bits, baud_, tolerance_bits_);
        report(SerialPeer::kSerialFraming, detail);
    }
}

// bit_index 0 = start bit, 1..8 data, 9 stop.
void SerialPeer::sample(unsigned bit_index) {
    const bool level = input_level(rx_pin_);
    if (bit_index == 0 && level) {  // a glitch, not a start bit
        receiving_ = false;
        return;
    }
    if (bit_index >= 1 && bit_index <= 8 && level) shift_ |= 1u << (bit_index - 1);
    if (bit_index == 9) {
        receiving_ = false;
        if (!level) {
            report(SerialPeer::kSerialFraming, "stop bit read 0 (framing error)");
            return;
        }
        received_.push_back(static_cast<char>(shift_));
        return;
    }
    clock().scheduler().at(bit_time(frame_start_, bit_index + 1.5), [this, bit_index](Cycle) { sample(bit_index + 1); });
}

}  // namespace avrbench
