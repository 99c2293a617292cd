// A serial device on two nets, working at the pin level: it decodes the
// frames the firmware sends on `rx` (a bit-banged TX such as SoftwareSerial,
// or a USART's TXD where the board wires one) and sends frames on `tx`, as a
// USB-serial adapter or a GPS module on a software serial port would. 8 data
// bits, no parity, 1 stop bit, LSB first, idle high (the asynchronous frame
// of ATmega328P §20.4, which SoftwareSerial imitates).
//
// Decoding: a falling edge while idle starts a frame; the peer samples the
// middle of each bit (as a receiver does, §20.8), and a stop bit that reads 0
// is a `serial-framing` finding. Bit timing is checked too: the firmware's
// edges must fall within `tolerance` of a bit (default 5 %: the receiver
// budget of §20.8, Table 20-2 for 8N1 is about +-4.5 %, both ends together).
#pragma once

#include <string>
#include <vector>

#include "parts/BitSerial.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class SerialPeer final : public Part {
public:
    // What this part finds (`avrbench findings` lists every kind).
    static const FindingKind kSerialFraming;  // serial-framing
    static std::vector<ParamSpec> param_specs();

    SerialPeer(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "serial_peer"; }
    void start() override;

    // Queues `bytes` to send, the first start bit at `at_cycle` (or when the
    // line is free).
    void send(const std::string& bytes, Cycle at_cycle);
    const std::string& received() const { return received_; }
    double bit_cycles() const { return line_.bit_cycles(); }
    // The longest deviation of a firmware edge from the bit grid of its frame, in bits.
    double worst_edge_error_bits() const { return worst_edge_error_bits_; }

private:
    void on_input(std::size_t pin, bool level) override;
    void on_edge(double bits);

    std::size_t rx_pin_ = 0, tx_pin_ = 0;
    double baud_;
    double tolerance_bits_;
    std::string send_at_start_;
    double send_at_s_;
    BitSerial line_;

    std::string received_;
    double worst_edge_error_bits_ = 0;
};

}  // namespace avrbench
