#include "periph/timer/CompareOutputPins.hpp"

#include <string_view>

extern "C" {
#include <avr_ioport.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"
#include "periph/interrupts/SimavrIrqHooks.hpp"

namespace avrbench {

namespace {
}  // namespace

struct CompareOutputPins::Port {
    CompareOutputPins* owner = nullptr;
    avr_ioport_t* io = nullptr;
    std::uint8_t connected = 0;  // pins a connected OCnx (or TxDn) drives
    std::uint8_t forced = 0;     // of those, the ones driven as outputs whatever DDxn says
    std::uint8_t level = 0;      // their OCnx level
    std::uint8_t shared = 0;     // pins with more than one comparator (2560 PB7: OC0A, OC1C)
    std::uint8_t waving = 0;     // pins handed out as periodic waves
    std::unique_ptr<IoWriteHook> port_write, pin_write, ddr_write, pcmsk_write;
    std::unique_ptr<IoReadHook> pin_read;

    std::uint8_t overridden(const avr_t* avr) const {
        return static_cast<std::uint8_t>(connected & (avr->data[io->r_ddr] | forced));
    }
    std::uint8_t effective(std::uint8_t port_value, std::uint8_t mask) const {
        return static_cast<std::uint8_t>((port_value & ~mask) | (level & mask));
    }
};

CompareOutputPins::CompareOutputPins(avr_t* avr)
    : avr_(avr), pin_write_toggles_(part_facts(avr).pin_write_toggles) {
    FixState<CompareOutputPins>::add(avr, this);
}

CompareOutputPins::~CompareOutputPins() { FixState<CompareOutputPins>::remove(avr_); }

CompareOutputPins* CompareOutputPins::of(const avr_t* avr) { return FixState<CompareOutputPins>::find(avr); }

CompareOutputPins::Port* CompareOutputPins::port_for(avr_ioport_t* io) {
    for (auto& p : ports_) {
        if (p->io == io) return p.get();
    }
    auto p = std::make_unique<Port>();
    p->owner = this;
    p->io = io;
    p->port_write = std::make_unique<IoWriteHook>(avr_, io->r_port, &on_port_write, p.get());
    p->pin_write = std::make_unique<IoWriteHook>(avr_, io->r_pin, &on_pin_write, p.get());
    p->ddr_write = std::make_unique<IoWriteHook>(avr_, io->r_ddr, &on_ddr_write, p.get());
    // pin_read comes with the port's first connected OCnx (combine): until
    // then PINx needs no correction, and polling loops read PINx constantly.
    ports_.push_back(std::move(p));
    return ports_.back().get();
}

int CompareOutputPins::add(avr_regbit_t com_pin, avr_irq_t* compare_irq) {
    if (com_pin.reg == 0) return -1;
    avr_ioport_t* io = nullptr;
    for (avr_io_t* m = avr_->io_port; m != nullptr; m = m->next) {
        if (m->kind == nullptr || std::string_view(m->kind) != "port") continue;
        auto* p = reinterpret_cast<avr_ioport_t*>(m);
        if (p->r_port == com_pin.reg) io = p;
    }
    if (io == nullptr) return -1;
    Driver d;
    d.port = port_for(io);
    d.bit = static_cast<std::uint8_t>(com_pin.bit);
    d.compare_irq = compare_irq;
    d.pin_irq = io->io.irq + com_pin.bit;
    for (const Driver& other : drivers_) {
        if (other.port == d.port && other.bit == d.bit) d.port->shared = static_cast<std::uint8_t>(d.port->shared | (1u << d.bit));
    }
    drivers_.push_back(d);
    avr_unconnect_irq(d.compare_irq, d.pin_irq);
    return static_cast<int>(drivers_.size() - 1);
}

int CompareOutputPins::add_forced_output(char port_letter, int bit) {
    avr_ioport_t* io = nullptr;
    for (avr_io_t* m = avr_->io_port; m != nullptr; m = m->next) {
        if (m->kind == nullptr || std::string_view(m->kind) != "port") continue;
        auto* p = reinterpret_cast<avr_ioport_t*>(m);
        if (p->name == port_letter) io = p;
    }
    if (io == nullptr || bit < 0 || bit > 7) return -1;
    Driver d;
    d.port = port_for(io);
    d.bit = static_cast<std::uint8_t>(bit);
    d.pin_irq = io->io.irq + bit;
    d.forces_output = true;
    drivers_.push_back(d);
    return static_cast<int>(drivers_.size() - 1);
}

bool CompareOutputPins::forces_output(const avr_ioport_t* io, int bit) const {
    for (const auto& p : ports_) {
        if (p->io == io) return ((p->forced & p->connected) >> bit & 1) != 0;
    }
    return false;
}

int CompareOutputPins::on_direction_change(std::function<void()> fn) {
    direction_listeners_.emplace_back(next_listener_id_, std::move(fn));
    return next_listener_id_++;
}

void CompareOutputPins::remove_direction_listener(int id) {
    std::erase_if(direction_listeners_, [id](const auto& l) { return l.first == id; });
}

void CompareOutputPins::tell_direction_listeners() {
    for (auto& [id, fn] : direction_listeners_) fn();
}

void CompareOutputPins::after_reset() {
    bool forced_was_connected = false;
    for (Driver& d : drivers_) {
        if (d.waving) end_wave(static_cast<int>(&d - drivers_.data()), avr_->cycle);
        forced_was_connected = forced_was_connected || (d.forces_output && d.connected);
        d.connected = false;
        d.level = false;
        if (d.compare_irq != nullptr) avr_unconnect_irq(d.compare_irq, d.pin_irq);
    }
    for (auto& p : ports_) {
        p->connected = 0;
        p->forced = 0;
        p->level = 0;
    }
    if (forced_was_connected) {
        tell_direction_listeners();
    }
}

void CompareOutputPins::set(int id, bool connected, bool level) {
    if (id < 0) return;
    Driver& d = drivers_[static_cast<std::size_t>(id)];
    if (d.connected == connected && d.level == level) return;
    const bool level_changed = d.level != level;
    const bool direction_changed = d.forces_output && d.connected != connected;
    d.connected = connected;
    d.level = level;
    // For anyone watching the comparator's own IRQ (it no longer reaches the pin).
    if (level_changed && d.compare_irq != nullptr) avr_raise_irq(d.compare_irq, level ? 1 : 0);
    update_pin(*d.port, d.bit);
    if (direction_changed) {
        tell_direction_listeners();
    }
}

void CompareOutputPins::combine(Port& port, std::uint8_t bit, std::uint8_t port_value) {
    const std::uint8_t mask = static_cast<std::uint8_t>(1u << bit);
    int n = 0;
    bool any = false, all = true;
    for (const Driver& d : drivers_) {
        if (d.port != &port || d.bit != bit || !d.connected) continue;
        ++n;
        any = any || d.level;
        all = all && d.level;
    }
    // ATmega2560 §19 "Output Compare Modulator (OCM1C0A)": with OC0A and OC1C
    // both connected to PB7, PORTB7 selects OR (1) or AND (0) of the two.
    const bool on = n == 1 ? any : ((port_value & mask) != 0 ? any : all);
    bool forced = false;
    for (const Driver& d : drivers_) forced = forced || (d.port == &port && d.bit == bit && d.connected && d.forces_output);
    port.forced = static_cast<std::uint8_t>(forced ? (port.forced | mask) : (port.forced & ~mask));
    port.connected = static_cast<std::uint8_t>(n != 0 ? (port.connected | mask) : (port.connected & ~mask));
    port.level = static_cast<std::uint8_t>(n != 0 && on ? (port.level | mask) : (port.level & ~mask));
    // Installed once and kept (a hook cannot leave simavr's chain while
    // others, e.g. the board's pin terminals, may sit in front of it).
    if (port.connected != 0 && !port.pin_read) port.pin_read = std::make_unique<IoReadHook>(avr_, port.io->r_pin, &on_pin_read, &port);
}

void CompareOutputPins::update_pin(Port& port, std::uint8_t bit) {
    avr_t* avr = avr_;
    const std::uint8_t mask = static_cast<std::uint8_t>(1u << bit);
    const bool was_forced = (port.forced & mask) != 0;
    combine(port, bit, avr->data[port.io->r_port]);
    // An input: OCnx is not visible (§15.6) - unless the driver forces the pin out (TxDn).
    if ((avr->data[port.io->r_ddr] & mask) == 0 && (port.forced & mask) == 0) {
        // A forced output (TXEN cleared) just let go of an input pin: it reads
        // its pull-up again, or whatever drives it from outside.
        if (was_forced && (port.io->external.pull_mask & mask) == 0) {
            const bool pull_up = (avr->data[port.io->r_port] & mask) != 0;
            avr_raise_irq(port.io->io.irq + bit, pull_up ? 1 : 0);
        }
        return;
    }
    const bool level = (port.connected & mask) != 0 ? (port.level & mask) != 0 : (avr->data[port.io->r_port] & mask) != 0;
    // The port module's pin IRQ: sets PINxn, raises pin change interrupts,
    // tells the pin's listeners (filtered: nothing happens when unchanged).
    avr_raise_irq(port.io->io.irq + bit, level ? 1 : 0);
}

void CompareOutputPins::on_port_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    auto* port = static_cast<Port*>(hook.context());
    if (port->waving != 0) port->owner->stop_waves(*port);
    if (port->connected == 0) {
        hook.write_original(avr, addr, value);
        return;
    }
    for (std::uint8_t bit = 0; port->shared != 0 && bit < 8; ++bit) {
        if ((port->shared >> bit) & 1) port->owner->combine(*port, bit, value);
    }
    const std::uint8_t ovr = port->overridden(avr);
    // simavr's port module raises every output pin from PORTx: let it see the
    // OCnx levels on the overridden pins, then keep the firmware's value.
    hook.write_original(avr, addr, port->effective(value, ovr));
    avr->data[addr] = value;
}

void CompareOutputPins::on_pin_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    auto* port = static_cast<Port*>(hook.context());
    if (port->waving != 0) port->owner->stop_waves(*port);
    const std::uint8_t ovr = port->overridden(avr);
    if (ovr == 0) {
        hook.write_original(avr, addr, value);
        return;
    }
    // Writing one to PINxn toggles PORTxn (§14.2.2); on an overridden pin that
    // is the firmware's PORTxn, not the pin.
    const avr_io_addr_t r_port = port->io->r_port;
    const std::uint8_t before = avr->data[r_port];
    const std::uint8_t toggles = port->owner->pin_write_toggles_ ? single_bit_write_value(avr, addr, value) : 0;
    if (port->owner->pin_write_toggles_ && (toggles & ~ovr) == 0) {
        // Only overridden pins: nothing for the port module to do.
        avr->data[r_port] = static_cast<std::uint8_t>(before ^ toggles);
        return;
    }
    avr->data[r_port] = port->effective(before, ovr);
    hook.write_original(avr, addr, static_cast<std::uint8_t>(value & ~ovr));
    avr->data[r_port] = static_cast<std::uint8_t>((avr->data[r_port] & ~ovr) | ((before ^ toggles) & ovr));
}

void CompareOutputPins::on_ddr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    auto* port = static_cast<Port*>(hook.context());
    if (port->waving != 0) port->owner->stop_waves(*port);
    if (port->connected == 0) {
        hook.write_original(avr, addr, value);
        return;
    }
    const avr_io_addr_t r_port = port->io->r_port;
    const std::uint8_t firmware_port = avr->data[r_port];
    const std::uint8_t ovr = static_cast<std::uint8_t>(port->connected & (value | port->forced));
    avr->data[r_port] = port->effective(firmware_port, ovr);
    hook.write_original(avr, addr, value);
    avr->data[r_port] = firmware_port;
}

std::uint8_t CompareOutputPins::on_pin_read(IoReadHook& hook, avr_t* avr, avr_io_addr_t addr) {
    auto* port = static_cast<Port*>(hook.context());
    if (port->waving != 0) port->owner->stop_waves(*port);
    const std::uint8_t value = hook.read_original(avr, addr);
    const std::uint8_t ovr = port->overridden(avr);
    // PINxn of an output reads the pin, i.e. OCnx while it is overridden.
    return ovr == 0 ? value : static_cast<std::uint8_t>((value & ~ovr) | (port->level & ovr));
}

// --- periodic waves -----------------------------------------------------------

void CompareOutputPins::set_sink(avr_ioport_t* io, int bit, PeriodicOutputSink* sink) {
    for (std::size_t i = 0; i < sinks_.size(); ++i) {
        if (sinks_[i].io != io || sinks_[i].bit != bit) continue;
        sinks_.erase(sinks_.begin() + static_cast<std::ptrdiff_t>(i));
        break;
    }
    if (sink != nullptr) sinks_.push_back({io, static_cast<std::uint8_t>(bit), sink});
}

PeriodicOutputSink* CompareOutputPins::sink_for(const Driver& d) const {
    for (const Sink& s : sinks_) {
        if (s.io == d.port->io && s.bit == d.bit) return s.sink;
    }
    return nullptr;
}

bool CompareOutputPins::only_known_listeners(const Driver& d, const PeriodicOutputSink& sink) const {
    // Nobody may watch the comparator's own IRQ, and on the pin only simavr's
    // port module (its notify's parameter is the port) and the sink's listener.
    if (irq_has_listeners(d.compare_irq)) return false;
    const void* allowed[2] = {d.port->io, sink.listener_param()};
    return irq_listeners_within(d.pin_irq, allowed, 2);
}

bool CompareOutputPins::begin_wave(int id, const PeriodicWave& wave, StopWave stop, void* timer) {
    if (id < 0) return false;
    Driver& d = drivers_[static_cast<std::size_t>(id)];
    Port& port = *d.port;
    const std::uint8_t mask = static_cast<std::uint8_t>(1u << d.bit);
    if (d.waving || !d.connected || d.level != wave.start_level) return false;
    if ((port.shared & mask) != 0 || (avr_->data[port.io->r_ddr] & mask) == 0) return false;
    avr_ioport_t* io = port.io;
    if (io->r_pcint != 0) {
        // simavr 1.6's avr_ioport_irq_notify raises PCIFx when PCMSK has the pin's bit.
        if ((avr_->data[io->r_pcint] & mask) != 0) return false;
    }
    PeriodicOutputSink* sink = sink_for(d);
    if (sink == nullptr || !only_known_listeners(d, *sink)) return false;
    if (!sink->begin_wave(wave)) return false;
    if (io->r_pcint != 0 && !port.pcmsk_write) {
        port.pcmsk_write = std::make_unique<IoWriteHook>(avr_, io->r_pcint, &on_pcmsk_write, &port);
    }
    d.waving = true;
    d.stop = stop;
    d.timer = timer;
    port.waving = static_cast<std::uint8_t>(port.waving | mask);
    return true;
}

void CompareOutputPins::end_wave(int id, Cycle at) {
    if (id < 0) return;
    Driver& d = drivers_[static_cast<std::size_t>(id)];
    if (!d.waving) return;
    d.waving = false;
    d.port->waving = static_cast<std::uint8_t>(d.port->waving & ~(1u << d.bit));
    if (PeriodicOutputSink* sink = sink_for(d)) sink->end_wave(at);
}

void CompareOutputPins::stop_all_waves() {
    for (Driver& d : drivers_) {
        if (d.waving) d.stop(d.timer, avr_->cycle);
    }
}

void CompareOutputPins::stop_waves(Port& port) {
    for (Driver& d : drivers_) {
        if (d.waving && d.port == &port) d.stop(d.timer, avr_->cycle);
    }
}

void CompareOutputPins::on_pcmsk_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    auto* port = static_cast<Port*>(hook.context());
    if (port->waving != 0) port->owner->stop_waves(*port);
    hook.write_original(avr, addr, value);
}

namespace {

class PortOverrides final : public Fix {
public:
    explicit PortOverrides(avr_t* avr) : pins_(avr) {}

private:
    CompareOutputPins pins_;
};

}  // namespace

std::unique_ptr<Fix> install_port_overrides(avr_t* avr) { return std::make_unique<PortOverrides>(avr); }

}  // namespace avrbench
