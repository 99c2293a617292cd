// The host end of a serial line, on the firmware's TX and RX nets: a
// USB-serial adapter (an Uno's ATmega16U2, an FTDI cable) and whatever runs
// behind it, chosen when the board runs - a G-code sender (`--gcode`, a
// scenario's job), a pty (`--pty`), raw bytes (`--uart-in`, `--uart-out`).
//
//   parts:
//     host: {type: serial_host, family: grbl, flow: character_counting}
//   nets:
//     host_rx: [uno.PD1, host.rx]   # the firmware's TXD
//     host_tx: [host.tx, uno.PD0]   # the firmware's RXD
//
// Where the two nets reach the TXDn and RXDn pins of one USART (ATmega328P
// Table 14-9, 2560 §13.3, m32 "Alternate Functions of Port D") the host works
// at byte level on that USART, as a real adapter's bytes reach the receiver:
// exact to the cycle and cheap (periph/usart/Uart; the host's frames are drawn on its
// tx net all the same). On any other pins it works at bit level, as a
// SoftwareSerial port needs: it decodes the frames the firmware bit-bangs on
// `rx` and sends frames on `tx` at `baud` (parts/BitSerial; 8N1).
//
// Its TX idles high from power-on: an adapter's transmitter holds the line at
// mark while it has nothing to say (the frame's idle state, §20.4).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "parts/BitSerial.hpp"
#include "parts/HostConnector.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class SerialHost final : public Part, public HostConnector {
public:
    // What this part finds (`avrbench findings` lists every kind).
    static const FindingKind kHostLineFraming;  // host-line-framing
    static std::vector<ParamSpec> param_specs();

    SerialHost(std::string name, Mcu& clock, const ParamValues& params);
    ~SerialHost() override;
    std::string_view type() const override { return "serial_host"; }
    void start() override;
    std::string summary() override;

    SerialLink& link() override;
    const HostProtocol& protocol() const override { return protocol_; }
    Uart* usart() const override { return usart_; }
    std::string link_text() const override { return link_text_; }

private:
    class PinLink;
    void on_input(std::size_t pin, bool level) override;
    // The one MCU pin on `pin`'s net, nullptr if none.
    Pin* mcu_pin_on_net(std::size_t pin);
    void drive_tx(bool high);

    std::size_t rx_pin_ = 0, tx_pin_ = 0;
    HostProtocol protocol_;
    double baud_;
    double series_ohms_;
    Uart* usart_ = nullptr;
    std::unique_ptr<PinLink> pin_link_;
    std::string link_text_;
};

}  // namespace avrbench
