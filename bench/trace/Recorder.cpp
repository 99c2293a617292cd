#include "trace/Recorder.hpp"

#include <optional>

#include <algorithm>

#include <cctype>
#include <sstream>

extern "C" {
#include <sim_avr.h>
#include <avr_ioport.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "periph/ports/McuPins.hpp"
#include "periph/twi/Twi.hpp"

namespace avrbench {

struct Recorder::PinSink {
    avr_t* avr;
    avr_irq_t* irq;
    Timeline* timeline;
    SignalId id;
    bool level;

    // simavr raises pin IRQs on every PORT write, changed or not, so an edge
    // is a change from the level this sink last recorded (the low byte is the
    // level: simavr ors AVR_IOPORT_OUTPUT = 0x100 into some raises).
    static void notify(avr_irq_t*, std::uint32_t value, void* param) {
        auto* sink = static_cast<PinSink*>(param);
        const bool level = (value & 0xff) != 0;
        if (level == sink->level) return;
        sink->level = level;
        sink->timeline->record(sink->id, sink->avr->cycle, level ? 1 : 0);
    }
};

Recorder::Recorder(Timeline& timeline) : timeline_(timeline) {}

Recorder::~Recorder() {
    for (auto& sink : pin_sinks_) avr_irq_unregister_notify(sink->irq, &PinSink::notify, sink.get());
}

SignalId Recorder::trace_pin(Mcu& mcu, Pin& pin) {
    // Traced already (`--trace PB5,PB5`, or a pin the board traces too): one signal.
    if (const long existing = timeline_.find(mcu.name(), pin.name()); existing >= 0) return static_cast<SignalId>(existing);
    // A pin handed out as a periodic wave would not tell this listener its
    // edges: end the waves (they do not begin again while it listens).
    mcu.settle_periodic_outputs();
    const SignalId id = timeline_.add_signal({mcu.name(), pin.name(), SignalKind::Wire, 1, mcu.frequency_hz()});
    const bool level = pin.level();
    timeline_.record(id, mcu.cycle(), level ? 1 : 0);
    pin_sinks_.push_back(std::make_unique<PinSink>(PinSink{mcu.avr(), pin.irq(), &timeline_, id, level}));
    avr_irq_register_notify(pin.irq(), &PinSink::notify, pin_sinks_.back().get());
    return id;
}

namespace {

// A USART's bytes in one direction: "uart<n>_tx" or "uart<n>_rx", shown as text.
SignalInfo uart_bytes(const Mcu& mcu, const Uart& uart, const char* direction) {
    return {mcu.name(), "uart" + std::to_string(uart.index()) + "_" + direction, SignalKind::Bus, 8, mcu.frequency_hz(),
            true};
}

}  // namespace

SignalId Recorder::trace_uart_tx(Mcu& mcu, Uart& uart) {
    const SignalId id = timeline_.add_signal(uart_bytes(mcu, uart, "tx"));
    Timeline* timeline = &timeline_;
    uart.on_transmit([timeline, id](Cycle cycle, std::uint8_t byte) { timeline->record(id, cycle, byte); });
    return id;
}

SignalId Recorder::trace_uart_rx(Mcu& mcu, Uart& uart) {
    const SignalId id = timeline_.add_signal(uart_bytes(mcu, uart, "rx"));
    Timeline* timeline = &timeline_;
    uart.on_receive([timeline, id](Cycle cycle, std::uint8_t byte) { timeline->record(id, cycle, byte); });
    return id;
}

SignalId Recorder::trace_twi(Mcu& mcu, Twi& twi) {
    const SignalId id = timeline_.add_signal({mcu.name(), "twi", SignalKind::Bus, 8, mcu.frequency_hz(), true});
    Timeline* timeline = &timeline_;
    twi.on_event([timeline, id](const TwiEvent& e) {
        if (e.kind == TwiEvent::Kind::Address || e.kind == TwiEvent::Kind::Data) timeline->record(id, e.cycle, e.byte);
    });
    return id;
}

std::vector<SignalId> Recorder::trace_part(Part& part) { return trace_part(part, {}); }

std::vector<SignalId> Recorder::trace_part(Part& part, const std::vector<std::string>& only) {
    for (const auto& name : only) {
        bool known = false;
        std::string names;
        for (const auto& s : part.signals()) {
            known = known || s.name == name;
            names += (names.empty() ? "" : ", ") + s.name;
        }
        if (!known) throw BadInput("part '" + part.name() + "' has no signal '" + name + "' (signals: " + (names.empty() ? "none" : names) + ")");
    }
    const auto wanted = [&](const std::string& name) { return only.empty() || std::find(only.begin(), only.end(), name) != only.end(); };
    part.clock().settle_periodic_outputs();  // a heater following a wave publishes no edges
    // Per part signal: its timeline signal, or none when not traced.
    std::vector<std::optional<SignalId>> by_signal;
    std::vector<SignalId> ids;
    for (const auto& s : part.signals()) {
        if (!wanted(s.name)) {
            by_signal.emplace_back();
            continue;
        }
        ids.push_back(timeline_.add_signal({part.name(), s.name, s.real ? SignalKind::Real : SignalKind::Wire, 1,
                                            part.clock().frequency_hz()}));
        by_signal.emplace_back(ids.back());
    }
    if (ids.empty()) return ids;
    Timeline* timeline = &timeline_;
    std::vector<bool> real;
    for (const auto& s : part.signals()) real.push_back(s.real);
    // The values at the moment tracing starts, so the trace has no unknowns.
    for (std::size_t i = 0; i < by_signal.size(); ++i) {
        if (!by_signal[i]) continue;
        const double v = part.signal_value(i);
        if (real[i]) {
            timeline_.record_real(*by_signal[i], part.clock().cycle(), v);
        } else {
            timeline_.record(*by_signal[i], part.clock().cycle(), v != 0 ? 1 : 0);
        }
    }
    part.watch_signals([timeline, by_signal, real](std::size_t signal, Cycle cycle, double value) {
        if (!by_signal[signal]) return;
        if (real[signal]) {
            timeline->record_real(*by_signal[signal], cycle, value);
        } else {
            timeline->record(*by_signal[signal], cycle, value != 0 ? 1 : 0);
        }
    });
    return ids;
}

std::vector<SignalId> Recorder::trace_pins(Mcu& mcu, const std::string& spec) {
    std::vector<std::string> names;
    std::stringstream ss(spec);
    std::string item;
    while (std::getline(ss, item, ',')) {
        while (!item.empty() && std::isspace(static_cast<unsigned char>(item.back()))) item.pop_back();
        while (!item.empty() && std::isspace(static_cast<unsigned char>(item.front()))) item.erase(0, 1);
        if (item.empty()) continue;
        std::string upper;
        for (char c : item) upper.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
        if (upper == "ALL") {
            for (char port = 'A'; port <= 'L'; ++port) {
                if (avr_io_getirq(mcu.avr(), AVR_IOCTL_IOPORT_GETIRQ(port), 0) == nullptr) continue;
                for (int bit = 0; bit < 8; ++bit) {
                if (mcu_has_pin(mcu.mcu_type(), port, bit)) names.push_back(std::string("P") + port + char('0' + bit));
                }
            }
        } else if (upper.size() == 5 && upper.rfind("PORT", 0) == 0) {
            for (int bit = 0; bit < 8; ++bit) {
                if (mcu_has_pin(mcu.mcu_type(), upper[4], bit)) names.push_back(std::string("P") + upper[4] + char('0' + bit));
            }
        } else {
            names.push_back(upper);
        }
    }
    if (names.empty()) throw BadInput("no pins in " + quoted_text(spec));
    std::vector<SignalId> ids;
    for (const auto& name : names) ids.push_back(trace_pin(mcu, mcu.pin(name)));
    return ids;
}

}  // namespace avrbench
