#include "parts/SerialHost.hpp"

#include <cstdio>

#include "core/Errors.hpp"
#include "periph/ports/McuPins.hpp"
#include "periph/ports/Pin.hpp"
#include "core/TextPattern.hpp"
#include "periph/usart/Uart.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(SerialHost, "serial_host");

const FindingKind SerialHost::kHostLineFraming = FindingKind::declare(
    "host-line-framing", "a frame the firmware bit-banged to a host with its stop bit low (a wrong bit rate or a frame cut short)",
    Severity::Warning);

std::vector<ParamSpec> SerialHost::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "family", .type = PT::Choice, .default_value = "generic",
         .choices = {"generic", "grbl", "marlin", "teacup", "repetier", "sprinter", "prusa"},
         .help = "what the firmware speaks: its welcome, keep-alives and answers (docs/THIRD_PARTY.md)"},
        {.name = "error_pattern", .type = PT::Text,
         .source = "the firmware's documentation of its error messages (its family's own are known: docs/HOSTS.md)",
         .help = "a regular expression (RE2) for lines the firmware prints on an error, besides its family's"},
        {.name = "flow", .type = PT::Choice, .default_value = "send_and_wait",
         .choices = {"send_and_wait", "character_counting"},
         .help = "one line then its answer, or grbl's character counting"},
        {.name = "rx_buffer", .type = PT::Integer, .default_value = "128",
         .source = "grbl 1.1 serial.h: RX_BUFFER_SIZE 128 on the ATmega328P",
         .help = "the firmware's receive buffer in bytes (character counting)", .min = 1, .max = 65536},
        {.name = "line_timeout", .type = PT::Quantity, .dimension = D::Time, .default_value = "0s",
         .source = "0: the family's (stimulus/UartHost.hpp default_line_timeout_s)",
         .help = "no answer for this long fails the job (keep-alives restart it)", .max = 3600},
        {.name = "series_resistance", .type = PT::Quantity, .dimension = D::Resistance, .default_value = "1kohm",
         .source = "Arduino UNO R3 schematic: RN4 puts 1 kohm between the ATmega16U2's TXD and the 328P's RXD",
         .help = "between the host's TX and the firmware's RX pin (0: driven directly, as an FTDI cable's); a sketch "
                 "that drives its RX pin as an output overrides the host through it, as on an UNO",
         .max = 1e6},
        {.name = "baud", .type = PT::Quantity, .default_value = "9600",
         .source = "SoftwareSerial examples: 9600 baud",
         .help = "bits per second on bit-banged pins (a USART's own setting rules on its pins)", .min = 50, .max = 2e6},
    };
}

// A bit-level link on the part's two pins.
class SerialHost::PinLink final : public SerialLink {
public:
    PinLink(SerialHost& host, double baud)
        : line_(host.clock(), baud,
                {.drive_tx = [&host](bool high) { host.drive_tx(high); },
                 .rx_level = [&host] { return host.input_level(host.rx_pin_); },
                 .on_byte = [this](Cycle start, std::uint8_t byte) { received(start, byte); },
                 .on_framing_error = [&host](Cycle) {
                     host.report(kHostLineFraming, "a frame on " + host.link_text() + " with its stop bit low");
                 },
                 .on_edge = {},
                 .on_sent = [this](Cycle at, std::uint8_t byte) {
                     for (auto& fn : deliver_listeners_) fn(at, byte);
                 }}),
          clock_(host.clock()) {}

    const std::vector<UartByte>& transmitted() const override { return transmitted_; }
    void on_transmit(ByteListener fn) override { listeners_.push_back(std::move(fn)); }
    void connect_host() override {}  // the part holds TX at mark from the start
    void send(const std::string& bytes) override { line_.send(bytes, clock_.cycle()); }
    // A byte is delivered when its stop bit begins: the receiver has its data.
    std::uint64_t bytes_delivered() const override { return line_.bytes_sent(); }
    void on_deliver(ByteListener fn) override { deliver_listeners_.push_back(std::move(fn)); }
    std::size_t pending_rx() const override { return static_cast<std::size_t>(line_.bytes_queued() - line_.bytes_sent()); }
    Cycle cycles_per_frame() const override { return line_.frame_cycles(); }
    void rx_edge(bool level) { line_.rx_edge(level); }

private:
    void received(Cycle start, std::uint8_t byte) {
        transmitted_.push_back({start, byte});
        for (auto& fn : listeners_) fn(start, byte);
    }

    BitSerial line_;
    Mcu& clock_;
    std::vector<UartByte> transmitted_;
    std::vector<ByteListener> listeners_;
    std::vector<ByteListener> deliver_listeners_;
};

SerialHost::SerialHost(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock), baud_(params.quantity("baud")), series_ohms_(params.quantity("series_resistance")) {
    protocol_.family = params.text("family");
    protocol_.flow = params.text("flow");
    protocol_.rx_buffer_bytes = static_cast<unsigned>(params.integer("rx_buffer"));
    protocol_.line_timeout_s = params.quantity("line_timeout");
    if (protocol_.line_timeout_s != 0 && protocol_.line_timeout_s < kShortestLineTimeout_s) {
        throw part_error(this->name(), "line_timeout must be 0 (the family's) or at least 100us: no firmware answers faster");
    }
    if (params.has("error_pattern")) {
        protocol_.error_pattern = params.text("error_pattern");
        (void)TextPattern(protocol_.error_pattern, "part '" + this->name() + "': error_pattern");
    }
    rx_pin_ = add_pin("rx", TerminalRole::Input);
    tx_pin_ = add_pin("tx", TerminalRole::Output);
}

SerialHost::~SerialHost() = default;

void SerialHost::drive_tx(bool high) {
    if (series_ohms_ > 0) {
        pull_output(tx_pin_, high, series_ohms_);
    } else {
        drive_output(tx_pin_, high);
    }
}

Pin* SerialHost::mcu_pin_on_net(std::size_t pin) {
    const Net* net = this->pin(pin).net();
    if (net == nullptr) return nullptr;
    for (const Terminal* t : net->terminals()) {
        if (t->mcu_pin() != nullptr && t->clock_mcu() == &clock()) return t->mcu_pin();
    }
    return nullptr;
}

void SerialHost::start() {
    Pin* txd = mcu_pin_on_net(rx_pin_);
    Pin* rxd = mcu_pin_on_net(tx_pin_);
    if (txd == nullptr || rxd == nullptr) {
        throw BadInput("part '" + name() + "' (serial_host): " + (txd == nullptr ? "rx" : "tx") +
                       " shares no net with a pin of MCU '" + clock().name() +
                       "' (rx joins the firmware's TX pin, tx its RX pin)");
    }
    drive_tx(true);  // idle: mark
    for (int index = 0; const auto pins = usart_pins(clock().mcu_type(), index); ++index) {
        const std::string tx_name = std::string("P") + pins->tx_port + static_cast<char>('0' + pins->tx_bit);
        const std::string rx_name = std::string("P") + pins->rx_port + static_cast<char>('0' + pins->rx_bit);
        if (txd->name() != tx_name || rxd->name() != rx_name) continue;
        usart_ = &clock().uart(index);
        usart_->host_drives_rx_line([this](bool high) { drive_tx(high); });
        link_text_ = "USART" + std::to_string(index) + " (" + tx_name + "/" + rx_name + ")";
        return;
    }
    char baud[32];
    std::snprintf(baud, sizeof baud, "%g", baud_);
    link_text_ = txd->name() + "/" + rxd->name() + " at " + baud + " baud";
    pin_link_ = std::make_unique<PinLink>(*this, baud_);
}

SerialLink& SerialHost::link() {
    if (usart_ != nullptr) return *usart_;
    if (pin_link_ == nullptr) throw part_error(name(), "the board has not started (no link yet)");
    return *pin_link_;
}

void SerialHost::on_input(std::size_t pin, bool level) {
    if (pin == rx_pin_ && pin_link_ != nullptr) pin_link_->rx_edge(level);
}

std::string SerialHost::summary() {
    const SerialLink& l = link();
    return link_text_ + (usart_ != nullptr ? ", byte level" : ", bit level") + ": " +
           std::to_string(l.transmitted().size()) + " bytes from the firmware";
}

}  // namespace avrbench
