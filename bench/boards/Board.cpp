#include "boards/Board.hpp"

#include <cmath>
#include <set>

#include "boards/PartRegistry.hpp"
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
            throw BadInput(decl.location + ": MCU '" + decl.name + "' has no firmware (give an ELF)");
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
        mcus_.push_back(std::make_unique<Mcu>(elf, options));
    }
}

void Board::build_parts() {
    // Each part is clocked by the MCU its nets lead to, else by the part it
    // refers to, else by the board's first MCU.
    std::map<std::string, Mcu*> clock_of;
    for (const auto& net : spec_.nets) {
        Mcu* net_mcu = nullptr;
        for (const auto& e : net.endpoints) {
            if (spec_.find_mcu(e.owner) != nullptr) net_mcu = &mcu(e.owner);
        }
        if (net_mcu == nullptr) continue;
        for (const auto& e : net.endpoints) {
            if (spec_.find_part(e.owner) != nullptr && clock_of.count(e.owner) == 0) clock_of[e.owner] = net_mcu;
        }
    }

    // A part with an analog input (adc_pin: mcu.PIN, a thermistor) is clocked
    // by that MCU: its ADC samples the part.
    for (const auto& decl : spec_.parts) {
        const RawParam* raw = find_param(decl, "adc_pin");
        if (raw == nullptr || clock_of.count(decl.name) != 0) continue;
        const auto dot = raw->value.find('.');
        if (dot != std::string::npos && spec_.find_mcu(raw->value.substr(0, dot)) != nullptr) {
            clock_of[decl.name] = &mcu(raw->value.substr(0, dot));
        }
    }

    std::map<std::string, Part*> built;
    std::set<std::string> pending;
    for (const auto& d : spec_.parts) pending.insert(d.name);
    while (!pending.empty()) {
        bool progress = false;
        for (const auto& decl : spec_.parts) {
            if (pending.count(decl.name) == 0) continue;
            auto type_it = part_types().find(decl.type);
            if (type_it == part_types().end()) {
                throw BadInput(decl.location + ": part '" + decl.name + "': unknown part type '" + decl.type +
                               "' (known: " + known_types() + ")");
            }
            const PartType& type = type_it->second;
            // References must name declared parts of the right type; wait
            // until those are built.
            bool ready = true;
            Mcu* referenced_clock = nullptr;
            for (const auto& [param, allowed] : type.references) {
                const RawParam* raw = find_param(decl, param);
                if (raw == nullptr) continue;  // resolve_params reports the missing required one
                const PartDecl* target = spec_.find_part(raw->value);
                if (target == nullptr) {
                    throw BadInput(raw->location + ": part '" + decl.name + "': " + param + " '" + raw->value +
                                   "' is not a part of this board");
                }
                bool type_ok = false;
                for (const auto& a : allowed) type_ok = type_ok || a == target->type;
                if (!type_ok) {
                    throw BadInput(raw->location + ": part '" + decl.name + "': " + param + " '" + raw->value +
                                   "' is a " + target->type + ", expected " + allowed.front());
                }
                auto b = built.find(raw->value);
                if (b == built.end()) {
                    ready = false;
                } else if (referenced_clock == nullptr) {
                    referenced_clock = &b->second->clock();
                }
            }
            if (!ready) continue;

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
            Mcu* clock = clock_of.count(decl.name) ? clock_of[decl.name]
                         : referenced_clock != nullptr ? referenced_clock
                                                       : mcus_.front().get();
            auto lookup = [&built](const std::string& n) -> Part& { return *built.at(n); };
            try {
                parts_.push_back(type.build(decl.name, *clock, values, lookup));
            } catch (const BadInput& e) {
                throw BadInput(decl.location + ": " + e.what());
            }
            built[decl.name] = parts_.back().get();
            pending.erase(decl.name);
            progress = true;
        }
        if (!progress) {
            const PartDecl* stuck = spec_.find_part(*pending.begin());
            throw BadInput(stuck->location + ": part '" + stuck->name + "' is part of a circular reference");
        }
    }
}

void Board::build_nets() {
    for (const auto& decl : spec_.nets) {
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
            Part& p = part(e.owner);
            PartPin* pin = p.find_pin(e.pin);
            if (pin == nullptr) {
                std::string list;
                for (std::size_t i = 0; i < p.pin_count(); ++i) list += (list.empty() ? "" : ", ") + p.pin(i).name();
                throw BadInput(e.location + ": part '" + p.name() + "' (" + std::string(p.type()) + ") has no pin '" +
                               e.pin + "' (pins: " + list + ")");
            }
            if (pin->role() == TerminalRole::Output) drivers.push_back(e.text());
            net->connect(*pin);
        }
        if (drivers.size() > 1) {
            throw BadInput(decl.location + ": net '" + decl.name + "' is driven by two outputs: " + drivers[0] + " and " +
                           drivers[1]);
        }
        nets_.push_back(std::move(net));
    }
    for (auto& n : nets_) {
        // Findings of a net carry the cycle of an MCU on it (else the board's first).
        Mcu* clock = mcus_.front().get();
        for (const auto& t : mcu_terminals_) {
            if (t->net() == n.get()) {
                clock = &t->mcu();
                break;
            }
        }
        n->set_clock(*clock);
    }
    build_twi_buses();
    for (auto& p : parts_) p->start();
    for (auto& n : nets_) n->settle();
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

McuPinTerminal& Board::add_mcu_terminal(Mcu& mcu, Pin& pin, Net& net) {
    mcu_terminals_.push_back(std::make_unique<McuPinTerminal>(mcu, pin));
    McuPinTerminal& terminal = *mcu_terminals_.back();
    net.connect(terminal);
    auto& watch = port_watches_[&mcu];
    if (!watch) watch = std::make_unique<McuPortWatch>(mcu);
    watch->add(terminal);
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

std::vector<Finding> Board::findings() const {
    std::vector<Finding> out;
    for (const auto& m : mcus_) out.insert(out.end(), m->findings().begin(), m->findings().end());
    for (const auto& p : parts_) out.insert(out.end(), p->findings().begin(), p->findings().end());
    for (const auto& n : nets_) out.insert(out.end(), n->findings().begin(), n->findings().end());
    return out;
}

}  // namespace avrbench
