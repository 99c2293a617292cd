#include "boards/Board.hpp"

#include "periph/ports/McuPins.hpp"

#include <cmath>
#include <set>

#include "parts/PartRegistry.hpp"
#include "periph/adc/Adc.hpp"
#include "core/Units.hpp"

namespace avrbench {
namespace {

std::string known_types() {
    std::string out;
    for (const auto& [name, type] : part_types()) out += (out.empty() ? "" : ", ") + name;
    return out;
}

const RawParam* find_param(const PartDecl& decl, const std::string& name) {
    for (const auto& p : decl.params) {
        if (p.name == name) return &p;
    }
    return nullptr;
}

}  // namespace

Board::Board(BoardSpec spec, const std::map<std::string, std::string>& firmware) : spec_(std::move(spec)) {
    build_mcus(firmware);
    build_parts();
    build_nets();
    for (auto& m : mcus_) lockstep_.add(*m);
    declare_influences();
}

// What one MCU can change that another sees: nets joining a pin or part on
// one MCU's clock to a pin or part on another's (the TWI bus is two such
// nets). Parts joined by ports share one clock (build_parts), so a path from
// one MCU through parts to another always ends on such a net.
void Board::declare_influences() {
    for (const auto& net : nets_) {
        for (const Terminal* from : net->terminals()) {
            for (const Terminal* to : net->terminals()) {
                Mcu* a = from->clock_mcu();
                Mcu* b = to->clock_mcu();
                if (a != nullptr && b != nullptr && a != b) lockstep_.add_influence(*a, *b, to->mcu_pin());
            }
        }
    }
}

Board::~Board() = default;

std::unique_ptr<Board> Board::from_file(const std::string& path, const std::map<std::string, std::string>& firmware) {
    return std::make_unique<Board>(load_board_file(path), firmware);
}

void Board::build_mcus(const std::map<std::string, std::string>& firmware) {
    for (const auto& [name, elf] : firmware) {
        if (spec_.find_mcu(name) == nullptr) throw BadInput(spec_.path + ": the board has no MCU '" + name + "'");
    }
    for (const auto& decl : spec_.mcus) {
        auto it = firmware.find(decl.name);
        const std::string elf_path = it != firmware.end() ? it->second : decl.firmware;
        if (elf_path.empty()) {
            throw BadInput(decl.location + ": MCU '" + decl.name + "' has no firmware: give it one (run --firmware " + decl.name + "=ELF, a scenario's firmware: {" + decl.name + ": ELF}, or the board file's firmware:)");
        }
        const ElfImage elf = ElfImage::load(elf_path);
        if (!elf.embedded_mcu().empty() && elf.embedded_mcu() != decl.type) {
            throw BadInput(elf_path + ": built for " + elf.embedded_mcu() + ", but " + decl.location + " declares MCU '" +
                           decl.name + "' as " + decl.type);
        }
        McuOptions options;
        options.name = decl.name;
        options.mcu_type = decl.type;
        options.frequency_hz = decl.clock_hz;
        options.fuses = decl.fuses;
        options.lock_bits = decl.lock_bits;
        options.bootloader_hex = decl.bootloader;
        options.watchdog_resets_expected = decl.watchdog_resets_expected;
        mcus_.push_back(std::make_unique<Mcu>(elf, options));
    }
}

void Board::build_parts() {
    // Parts joined by nets without an MCU pin (ports: a motor's shaft and its
    // axis, a carriage and its switches, a heater and its block) call each
    // other directly, so they share one clock: the MCU of the first net (in
    // the file's order) that joins one of them to an MCU pin (the net's last
    // MCU pin, when it has several); else the board's first MCU. Across
    // clocks, parts and MCUs meet only on nets, which the lockstep times
    // exactly (mcu/Lockstep.hpp).
    std::map<std::string, std::string> group_of;  // part -> its group's representative part
    const auto find = [&group_of](std::string name) {
        while (group_of.count(name) != 0 && group_of[name] != name) name = group_of[name];
        return name;
    };
    for (const auto& decl : spec_.parts) group_of[decl.name] = decl.name;
    // An observer's ports join nothing (PartType::observer).
    const auto grouped = [this](const std::string& owner) {
        const PartDecl* part = spec_.find_part(owner);
        if (part == nullptr) return false;
        const auto type = part_types().find(part->type);
        return type == part_types().end() || !type->second.observer;
    };
    for (const auto& net : spec_.nets) {
        bool has_mcu = false;
        for (const auto& e : net.endpoints) has_mcu = has_mcu || spec_.find_mcu(e.owner) != nullptr;
        if (has_mcu) continue;
        std::string first;
        for (const auto& e : net.endpoints) {
            if (!grouped(e.owner)) continue;
            if (first.empty()) first = find(e.owner);
            else group_of[find(e.owner)] = first;
        }
    }
    std::map<std::string, Mcu*> group_clock;
    for (const auto& net : spec_.nets) {
        Mcu* net_mcu = nullptr;
        for (const auto& e : net.endpoints) {
            if (spec_.find_mcu(e.owner) != nullptr) net_mcu = &mcu(e.owner);
        }
        if (net_mcu == nullptr) continue;
        for (const auto& e : net.endpoints) {
            if (grouped(e.owner)) group_clock.emplace(find(e.owner), net_mcu);
        }
    }
    std::map<std::string, Mcu*> clock_of;
    for (const auto& decl : spec_.parts) {
        auto it = group_clock.find(find(decl.name));
        if (it != group_clock.end()) clock_of[decl.name] = it->second;
    }

    for (const auto& decl : spec_.parts) {
        auto type_it = part_types().find(decl.type);
        if (type_it == part_types().end()) {
            throw BadInput(decl.location + ": part '" + decl.name + "': unknown part type '" + decl.type +
                           "' (known: " + known_types() + ")");
        }
        const PartType& type = type_it->second;
        std::map<std::string, std::string> preset = type.implied;
        if (!type.presets.empty()) {
            const RawParam* raw = find_param(decl, "preset");
            std::string preset_name = raw != nullptr ? raw->value : "";
            if (preset_name.empty()) {
                for (const auto& spec : type.params) {
                    if (spec.name == "preset") preset_name = spec.default_value;
                }
            }
            auto p = type.presets.find(preset_name);
            if (p != type.presets.end()) {
                for (const auto& [k, v] : p->second) preset[k] = v;
            }
        }
        const ParamValues values = resolve_params(type.params, preset, decl.params, decl.name, decl.location);
        auto clock = clock_of.find(decl.name);
        try {
            parts_.push_back(type.build(decl.name, clock != clock_of.end() ? *clock->second : *mcus_.front(), values));
        } catch (const BadInput& e) {
            throw BadInput(decl.location + ": " + e.what());
        }
    }
}

namespace {

std::string pins_and_ports(Part& p) {
    std::string list;
    for (std::size_t i = 0; i < p.pin_count(); ++i) list += (list.empty() ? "" : ", ") + p.pin(i).name();
    std::string ports;
    for (std::size_t i = 0; i < p.port_count(); ++i) {
        ports += (ports.empty() ? "" : ", ") + p.port(i).name + " (" + std::string(p.port(i).kind->name) +
                 (p.port(i).provides ? "" : " in") + ")";
    }
    return "pins: " + (list.empty() ? std::string("none") : list) + "; ports: " + (ports.empty() ? "none" : ports);
}

}  // namespace

void Board::build_nets() {
    std::vector<PortLink> links;
    for (const auto& decl : spec_.nets) build_net(decl, links);
    connect_ports(links);
    set_net_clocks();
    build_twi_buses();
    for (auto& p : parts_) {
        try {
            p->start();
        } catch (const BadInput& e) {
            throw BadInput(spec_.find_part(p->name())->location + ": " + e.what());
        }
    }
    for (auto& n : nets_) n->settle();
}

// One net of the board file: an electrical net of pins, an analog net, or
// ports of one interface (their links go to `links`).
void Board::build_net(const NetDecl& decl, std::vector<PortLink>& links) {
    struct PortEnd {
        Part* part;
        std::size_t port;
        const Endpoint* endpoint;
    };
    std::vector<PortEnd> ports;
    std::vector<const Endpoint*> pins;
    for (const auto& e : decl.endpoints) {
        if (spec_.find_mcu(e.owner) != nullptr) {
            pins.push_back(&e);
            continue;
        }
        Part& p = part(e.owner);
        std::size_t index = 0;
        if (p.find_pin(e.pin) != nullptr) {
            pins.push_back(&e);
        } else if (p.find_port(e.pin, &index) != nullptr) {
            ports.push_back({&p, index, &e});
        } else {
            throw BadInput(e.location + ": part '" + p.name() + "' (" + std::string(p.type()) + ") has no pin or port '" +
                           e.pin + "' (" + pins_and_ports(p) + ")");
        }
    }
    if (ports.empty()) {
        build_electrical_net(decl);
        return;
    }
    // Ports of one kind, exactly one of them providing it.
    const PortInfo& first = ports.front().part->port(ports.front().port);
    const PortEnd* provider = nullptr;
    for (const PortEnd& end : ports) {
        const PortInfo& info = end.part->port(end.port);
        if (info.kind != first.kind) {
            throw BadInput(decl.location + ": net '" + decl.name + "' joins a " + std::string(first.kind->name) +
                           " port (" + ports.front().endpoint->text() + ") and a " +
                           std::string(info.kind->name) + " port (" + end.endpoint->text() + ")");
        }
        if (!info.provides) continue;
        if (provider != nullptr) {
            throw BadInput(decl.location + ": net '" + decl.name + "' has two " +
                           std::string(info.kind->name) + " providers: " + provider->endpoint->text() +
                           " and " + end.endpoint->text());
        }
        provider = &end;
    }
    if (provider == nullptr) {
        throw BadInput(decl.location + ": net '" + decl.name + "' has no part providing its " +
                       std::string(first.kind->name) + " port (" + ports.front().endpoint->text() +
                       " needs one, e.g. " + std::string(first.kind->example) + ")");
    }
    if (first.kind == &kAnalogPort) {
        build_analog_net(decl, *provider->part, provider->port, pins);
        return;
    }
    if (!pins.empty()) {
        throw BadInput(pins.front()->location + ": net '" + decl.name + "' joins the pin " + pins.front()->text() +
                       " and the " + std::string(first.kind->name) + " port " +
                       provider->endpoint->text() + ": only analog outputs share a net with pins");
    }
    for (const PortEnd& end : ports) {
        if (&end != provider) links.push_back({end.part, end.port, provider->part, provider->port});
    }
}

// Ports are connected part by part in declaration order (the order
// listeners are called in), then every required one must be.
void Board::connect_ports(const std::vector<PortLink>& links) {
    for (auto& p : parts_) {
        for (std::size_t port = 0; port < p->port_count(); ++port) {
            const PortInfo& info = p->port(port);
            const PortLink* link = nullptr;
            for (const auto& l : links) {
                if (l.part == p.get() && l.port == port) link = &l;
            }
            const std::string location = spec_.find_part(p->name())->location;
            if (link == nullptr) {
                if (info.required) {
                    throw BadInput(location + ": part '" + p->name() + "' (" + std::string(p->type()) + "): port '" +
                                   info.name + "' is not connected: join it to " + info.help + " in nets:");
                }
                continue;
            }
            try {
                p->connect_port(port, *link->provider, link->provider_port);
            } catch (const BadInput& e) {
                throw BadInput(location + ": " + e.what());
            }
        }
    }

}

// Findings of a net carry the cycle of an MCU on it (else the board's first).
void Board::set_net_clocks() {
    for (auto& n : nets_) {
        Mcu* clock = mcus_.front().get();
        for (const auto& t : mcu_terminals_) {
            if (t->net() == n.get()) {
                clock = &t->mcu();
                break;
            }
        }
        n->set_clock(*clock);
    }
}

void Board::build_electrical_net(const NetDecl& decl) {
    auto net = std::make_unique<Net>(decl.name);
    std::vector<std::string> drivers;
    for (const auto& e : decl.endpoints) {
        if (spec_.find_mcu(e.owner) != nullptr) {
            Mcu& m = mcu(e.owner);
            Pin* pin = nullptr;
            try {
                pin = &m.pin(e.pin);
            } catch (const BadInput& err) {
                throw BadInput(e.location + ": " + err.what());
            }
            add_mcu_terminal(m, *pin, *net);
            continue;
        }
        PartPin* pin = part(e.owner).find_pin(e.pin);
        if (pin->role() == TerminalRole::Output) drivers.push_back(e.text());
        net->connect(*pin);
    }
    if (drivers.size() > 1) {
        throw BadInput(decl.location + ": net '" + decl.name + "' is driven by two outputs: " + drivers[0] + " and " +
                       drivers[1]);
    }
    nets_.push_back(std::move(net));
}

void Board::build_analog_net(const NetDecl& decl, Part& source, std::size_t port,
                             const std::vector<const Endpoint*>& pins) {
    // The ADC of every MCU pin on the net samples the output's voltage, at
    // the start of each conversion. The output answers in its own clock's
    // cycles, so it must be clocked by that MCU.
    for (const Endpoint* e : pins) {
        if (spec_.find_mcu(e->owner) == nullptr) {
            throw BadInput(e->location + ": net '" + decl.name + "' joins the analog output " + source.name() + "." +
                           source.port(port).name + " and the digital pin " + e->text() +
                           ": an analog net holds MCU pins only");
        }
        Mcu& m = mcu(e->owner);
        if (&m != &source.clock()) {
            throw BadInput(e->location + ": " + source.name() + "." + source.port(port).name + " is clocked by MCU '" +
                           source.clock().name() + "' and cannot also be sampled by '" + m.name() + "'");
        }
        int channel = 0;
        try {
            channel = m.adc().channel_for_pin(e->pin);
        } catch (const BadInput& err) {
            throw BadInput(e->location + ": " + err.what());
        }
        m.adc().connect(channel, [&source, port](Cycle cycle) { return source.analog_volts(port, cycle); });
    }
}

Net* Board::net_of(Mcu& mcu, const std::string& pin_name) const {
    Pin* pin = &mcu.pin(pin_name);
    for (const auto& t : mcu_terminals_) {
        if (&t->mcu() == &mcu && &t->pin() == pin) return t->net();
    }
    return nullptr;
}

void Board::build_twi_buses() {
    // Two TWI modules talk when their SDA pins share a net and their SCL pins
    // share a net, as on the real board (the pull-ups are the nets' business).
    struct Lines {
        Twi* twi;
        Net* sda;
        Net* scl;
    };
    std::vector<Lines> wired;
    for (const auto& m : mcus_) {
        Twi* twi = m->twi();
        if (twi == nullptr) continue;
        const TwiPins pins = twi_pins(m->mcu_type());
        Lines lines{twi, net_of(*m, pins.sda), net_of(*m, pins.scl)};
        if (lines.sda != nullptr || lines.scl != nullptr) wired.push_back(lines);
    }
    for (std::size_t i = 0; i < wired.size(); ++i) {
        for (std::size_t j = i + 1; j < wired.size(); ++j) {
            const Lines& a = wired[i];
            const Lines& b = wired[j];
            const bool sda_shared = a.sda != nullptr && a.sda == b.sda;
            const bool scl_shared = a.scl != nullptr && a.scl == b.scl;
            if (sda_shared == scl_shared) continue;
            // SDA shared without SCL (or the reverse) is a wiring mistake, not a bus.
            const Net* shared = sda_shared ? a.sda : a.scl;
            std::string location = spec_.path;
            for (const auto& decl : spec_.nets) {
                if (decl.name == shared->name()) location = decl.location;
            }
            throw BadInput(location + ": net '" + shared->name() + "' joins the TWI " + (sda_shared ? "SDA" : "SCL") +
                           " pins of " + a.twi->owner_name() + " and " + b.twi->owner_name() + " but their " +
                           (sda_shared ? "SCL" : "SDA") + " pins are not on one net");
        }
    }
    std::map<std::pair<Net*, Net*>, TwiBus*> by_lines;
    for (const Lines& lines : wired) {
        auto& bus = by_lines[{lines.sda, lines.scl}];
        if (bus == nullptr) {
            twi_buses_.push_back(std::make_unique<TwiBus>());
            bus = twi_buses_.back().get();
        }
        lines.twi->attach(*bus);
    }
}

void Board::set_periodic_waves(bool on) {
    periodic_waves_ = on;
    for (const auto& t : mcu_terminals_) {
        if (on) {
            t->register_as_sink();
        } else {
            t->mcu().settle_periodic_outputs();  // a running wave ends here
            t->unregister_as_sink();
        }
    }
}

McuPinTerminal& Board::add_mcu_terminal(Mcu& mcu, Pin& pin, Net& net) {
    mcu_terminals_.push_back(std::make_unique<McuPinTerminal>(mcu, pin));
    McuPinTerminal& terminal = *mcu_terminals_.back();
    net.connect(terminal);
    auto& watch = port_watches_[&mcu];
    if (!watch) watch = std::make_unique<McuPortWatch>(mcu);
    watch->add(terminal);
    if (periodic_waves_) terminal.register_as_sink();
    // A USART's RxDn on a net hears the frames the net carries.
    for (int index = 0; const auto pins = usart_pins(mcu.mcu_type(), index); ++index) {
        if (pin.name() == std::string("P") + pins->rx_port + static_cast<char>('0' + pins->rx_bit)) {
            mcu.uart(index).listen_to_rx_line();
        }
    }
    return terminal;
}

namespace {

// A scenario's hand on a pin: a push-pull source it switches on and off.
class StimulusTerminal final : public Terminal {
public:
    explicit StimulusTerminal(std::string label) : label_(std::move(label)) {}
    std::string label() const override { return label_; }
    TerminalRole role() const override { return TerminalRole::Output; }
    Drive drive_state() const override { return drive_; }
    void receive(const Resolution&) override {}
    void set(const Drive& drive) {
        drive_ = drive;
        drive_changed();
    }

private:
    std::string label_;
    Drive drive_;
};

}  // namespace

Terminal& Board::stimulus_for(const std::string& endpoint_or_label) {
    Pin& target = pin(endpoint_or_label);
    auto& slot = stimuli_[&target];
    if (slot) return *slot;
    Net* net = nullptr;
    for (const auto& t : mcu_terminals_) {
        if (&t->pin() == &target) net = t->net();
    }
    if (net == nullptr) {
        Mcu* owner = nullptr;
        for (auto& m : mcus_) {
            if (m->avr() == target.avr()) owner = m.get();
        }
        nets_.push_back(std::make_unique<Net>(endpoint_or_label));
        net = nets_.back().get();
        net->set_clock(*owner);
        add_mcu_terminal(*owner, target, *net);
    }
    slot = std::make_unique<StimulusTerminal>("stimulus(" + endpoint_or_label + ")");
    net->connect(*slot);
    net->settle();
    return *slot;
}

void Board::drive_pin(const std::string& endpoint_or_label, bool level) {
    static_cast<StimulusTerminal&>(stimulus_for(endpoint_or_label)).set(Drive::strong(level));
}

void Board::release_pin(const std::string& endpoint_or_label) {
    static_cast<StimulusTerminal&>(stimulus_for(endpoint_or_label)).set(Drive::none());
}

Mcu& Board::mcu(const std::string& name) {
    if (name.empty()) return *mcus_.front();
    for (auto& m : mcus_) {
        if (m->name() == name) return *m;
    }
    throw BadInput("the board has no MCU '" + name + "'");
}

std::vector<Mcu*> Board::mcus() const {
    std::vector<Mcu*> out;
    for (const auto& m : mcus_) out.push_back(m.get());
    return out;
}

Part& Board::part(const std::string& name) {
    for (auto& p : parts_) {
        if (p->name() == name) return *p;
    }
    throw BadInput("the board has no part '" + name + "'");
}

std::vector<Part*> Board::parts() const {
    std::vector<Part*> out;
    for (const auto& p : parts_) out.push_back(p.get());
    return out;
}

Pin& Board::pin(const std::string& endpoint_or_label) {
    std::string text = endpoint_or_label;
    for (const auto& l : spec_.labels) {
        if (l.name == text) text = l.endpoint.text();
    }
    const auto dot = text.find('.');
    if (dot == std::string::npos) throw BadInput("'" + endpoint_or_label + "' is not mcu.PIN or a label");
    return mcu(text.substr(0, dot)).pin(text.substr(dot + 1));
}

StopReason Board::run_until_seconds(double seconds) {
    return run_until_ps(ps_from_seconds(seconds, "run_until_seconds"));
}

StopReason Board::run_for_seconds(double seconds) {
    return run_until_ps(add_ps(now_ps(), ps_from_seconds(seconds, "run_for_seconds")));
}

std::size_t Board::finding_count() const {
    std::size_t n = 0;
    for (const auto& m : mcus_) n += m->findings().size();
    for (const auto& p : parts_) n += p->findings().size();
    for (const auto& net : nets_) n += net->findings().size();
    return n;
}

std::vector<Finding> Board::findings() const {
    std::vector<Finding> out;
    for (const auto& m : mcus_) out.insert(out.end(), m->findings().begin(), m->findings().end());
    for (const auto& p : parts_) {
        out.insert(out.end(), p->findings().begin(), p->findings().end());
        for (Finding& f : p->pending_findings()) out.push_back(std::move(f));
    }
    for (const auto& n : nets_) out.insert(out.end(), n->findings().begin(), n->findings().end());
    return out;
}

}  // namespace avrbench
