// A part where a host program attaches to the firmware: the byte link it
// offers and how the host should talk on it. The bench attaches G-code
// senders, pty bridges and raw byte files to these parts by name, without
// knowing their type (parts/SerialHost is one).
#pragma once

#include <string>

#include "core/SerialLink.hpp"

namespace avrbench {

class Uart;

// The shortest line timeout a board may give (0 aside, the family's): a
// firmware's answer is at least a few frames after the line's last one
// (an "ok" and its line end at 1 Mbaud take 40 us).
constexpr double kShortestLineTimeout_s = 100e-6;

// How a host talks to the firmware behind this connector (the spelling of
// board files: stimulus/UartHost.hpp parses it).
struct HostProtocol {
    std::string family = "generic";      // stimulus/HostFamily.hpp: grbl, marlin, teacup, ...
    std::string flow = "send_and_wait";  // or character_counting
    unsigned rx_buffer_bytes = 128;      // the firmware's receive buffer (character counting)
    double line_timeout_s = 0;           // 0: the family's
    std::string error_pattern;           // a regular expression for error lines besides the family's ("": none)
};

class HostConnector {
public:
    virtual ~HostConnector() = default;
    // The link to the firmware; valid once the board has started its parts.
    virtual SerialLink& link() = 0;
    virtual const HostProtocol& protocol() const = 0;
    // The USART behind the link when it is one (its bytes are traced as a
    // bus), nullptr for a bit-level link.
    virtual Uart* usart() const = 0;
    // For messages and the summary: "USART0 (PD1/PD0)", "PB3/PB2 at 9600 baud".
    virtual std::string link_text() const = 0;
};

}  // namespace avrbench
