#include "parts/Part.hpp"

#include <algorithm>
#include <cmath>

#include "core/Errors.hpp"

namespace avrbench {

Mcu* PartPin::clock_mcu() const { return &part_.clock(); }

std::string PartPin::label() const { return part_.name() + "." + name_; }

void PartPin::receive(const Resolution& resolution) {
    if (resolution.level == level_) return;
    level_ = resolution.level;
    if (role_ == TerminalRole::Input) part_.on_input(index_, level_);
}

bool PartPin::begin_wave(const PeriodicWave& wave) {
    return role_ == TerminalRole::Input && part_.begin_input_wave(index_, wave);
}

void PartPin::end_wave(Cycle at) { part_.end_input_wave(index_, at); }

void PartPin::set_drive(const Drive& drive) {
    if (drive == drive_) return;
    drive_ = drive;
    drive_changed();
}

void PartPin::set_level(bool level) { set_drive(Drive::strong(level)); }

void PartPin::set_weak(bool level, double ohms) { set_drive(Drive::weak(level, ohms)); }

void PartPin::set_released() { set_drive(Drive::none()); }

PartPin* Part::find_pin(std::string_view name) {
    for (auto& p : pins_) {
        if (p->name() == name) return p.get();
    }
    return nullptr;
}

std::size_t Part::add_pin(std::string name, TerminalRole role) {
    pins_.push_back(std::make_unique<PartPin>(*this, pins_.size(), std::move(name), role));
    return pins_.size() - 1;
}

const PortInfo* Part::find_port(std::string_view name, std::size_t* index) const {
    for (std::size_t i = 0; i < ports_.size(); ++i) {
        if (ports_[i].name == name) {
            if (index != nullptr) *index = i;
            return &ports_[i];
        }
    }
    return nullptr;
}

void Part::connect_port(std::size_t port, Part& provider, std::size_t provider_port) {
    const PortInfo& info = ports_.at(port);
    const PortInfo& offered = provider.ports_.at(provider_port);
    if (info.provides || !offered.provides || info.kind != offered.kind || !connect_[port]) {
        throw BadInput("part '" + name_ + "' (" + std::string(type()) + ") cannot connect port '" + info.name + "' to '" +
                       provider.name() + "." + offered.name + "'");
    }
    connect_[port](provider.offered_[provider_port], provider);
}

double Part::analog_volts(std::size_t port, Cycle cycle) const { return analog_sources_.at(port)(cycle); }

std::size_t Part::add_port(PortInfo info, void* offered, std::function<void(void*, Part&)> connect) {
    ports_.push_back(std::move(info));
    offered_.push_back(offered);
    connect_.push_back(std::move(connect));
    analog_sources_.emplace_back();
    return ports_.size() - 1;
}

std::size_t Part::provide_analog(std::string name, std::function<double(Cycle)> volts, std::string help) {
    const std::size_t index = add_port({std::move(name), &kAnalogPort, true, false, std::move(help)}, nullptr, {});
    analog_sources_[index] = std::move(volts);
    return index;
}

std::size_t Part::add_signal(std::string name, bool real, double initial) {
    return add_signal({std::move(name), real, "", "", ""}, initial);
}

std::size_t Part::add_signal(PartSignalInfo info, double initial) {
    signal_infos_.push_back(std::move(info));
    signal_values_.push_back(initial);
    signal_changes_.push_back(0);
    return signal_infos_.size() - 1;
}

void Part::publish(std::size_t signal, double value) {
    signal_values_[signal] = value;
    if (trace_resolution_ > 0 && signal_infos_[signal].real) {
        // A deadband, not rounding: a value dithering about a rounding
        // boundary (a PWM-heated block's ripple) would be recorded at every swing.
        if (traced_values_.size() < signal_infos_.size()) traced_values_.resize(signal_infos_.size(), std::nan(""));
        const double last = traced_values_[signal];
        if (!std::isnan(last) && std::abs(value - last) < trace_resolution_) return;
        traced_values_[signal] = value;
    }
    ++signal_changes_[signal];
    const Cycle now = clock_->cycle();
    for (auto& fn : signal_listeners_) fn(signal, now, value);
}

void Part::inject_fault(const std::string& fault, Cycle at_cycle) {
    const auto names = fault_names();
    if (fault != "none" && std::find(names.begin(), names.end(), fault) == names.end()) {
        std::string list = "none";
        for (const auto& n : names) list += ", " + n;
        throw BadInput("part '" + name_ + "' (" + std::string(type()) + ") has no fault '" + fault + "' (faults: " +
                       list + ")");
    }
    clock_->scheduler().at(at_cycle, [this, fault](Cycle) {
        fault_ = fault;
        fault_history_.push_back({clock_->cycle(), fault});
        apply_fault(fault);
    });
}

void Part::inject_fault_at_seconds(const std::string& fault, double seconds) {
    inject_fault(fault, clock_->cycles_from_seconds(seconds));
}

std::size_t Part::report(FindingKind kind, std::string detail) {
    Finding f;
    f.kind = kind;
    f.source = name_;
    f.cycle = clock_->cycle();
    f.clock_hz = clock_->frequency_hz();
    f.has_pc = false;
    f.detail = std::move(detail);
    return findings_.record(std::move(f));
}

void Part::act(const std::string& action, const std::vector<double>& arguments) {
    (void)arguments;
    std::string list;
    for (const auto& a : actions()) list += (list.empty() ? "" : ", ") + a.name;
    throw part_error(name(), "has no action '" + action + "' (actions: " + (list.empty() ? "none" : list) + ")");
}

}  // namespace avrbench
