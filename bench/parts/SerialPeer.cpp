#include "parts/SerialPeer.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
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
      send_at_s_(params.quantity("send_at")),
      line_(clock, baud_,
            {.drive_tx = [this](bool high) { drive_output(tx_pin_, high); },
             .rx_level = [this] { return input_level(rx_pin_); },
             .on_byte = [this](Cycle, std::uint8_t byte) { received_.push_back(static_cast<char>(byte)); },
             .on_framing_error = [this](Cycle) { report(SerialPeer::kSerialFraming, "stop bit read 0 (framing error)"); },
             .on_edge = [this](double bits) { on_edge(bits); }}) {
    // 50 baud (teleprinters) to 2 Mbaud (the fastest USART setting at 16 MHz, U2X: §20.3.1).
    if (!(baud_ >= 50 && baud_ <= 2e6)) throw part_error(this->name(), "baud must be from 50 to 2000000");
    if (!(tolerance_bits_ > 0 && tolerance_bits_ < 0.5)) {
        throw part_error(this->name(), "tolerance must be more than 0 and less than half a bit");
    }
    if (!(send_at_s_ >= 0 && send_at_s_ <= 1e6)) throw part_error(this->name(), "send_at must be from 0 to 1e6 s");
    rx_pin_ = add_pin("rx", TerminalRole::Input);
    tx_pin_ = add_pin("tx", TerminalRole::Output);
}

void SerialPeer::start() {
    drive_output(tx_pin_, true);  // idle: mark
    if (!send_at_start_.empty()) send(send_at_start_, clock().cycles_from_seconds(send_at_s_));
}

void SerialPeer::send(const std::string& bytes, Cycle at_cycle) { line_.send(bytes, at_cycle); }

void SerialPeer::on_input(std::size_t pin, bool level) {
    if (pin == rx_pin_) line_.rx_edge(level);
}

void SerialPeer::on_edge(double bits) {
    // An edge inside a frame belongs on a bit boundary.
    const double error_bits = std::fabs(bits - std::round(bits));
    worst_edge_error_bits_ = std::max(worst_edge_error_bits_, error_bits);
    if (error_bits > tolerance_bits_) {
        char detail[128];
        std::snprintf(detail, sizeof detail, "edge %.3f bits into a frame: off the %g-baud bit grid by more than %g bit",
                      bits, baud_, tolerance_bits_);
        report(SerialPeer::kSerialFraming, detail);
    }
}

}  // namespace avrbench
