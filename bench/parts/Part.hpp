// A model of one real component: its pins and ports, parameters (with units
// and sources), state, and how it evolves between pin events. A part knows
// nothing of its neighbours; the board's nets connect its pins and ports.
//
// Connections, one mechanism (docs/ARCHITECTURE.md "Connection model"): a
// board net joins endpoints "owner.name". A digital pin (PartPin) joins MCU
// pins and other part pins on an electrical net. Every other coupling is a
// typed port: a part provides a port (a thermal body, a step output, winding
// drives, an analog voltage) or requires one, and a net joins one provider
// with the ports that require its kind. The board calls connect_port() on
// the requiring part with the provider, before start().
//
// Time: a part is clocked by one MCU of the board (the one its nets lead to):
// clock().cycle() is "now", clock().scheduler() schedules its own events.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/Errors.hpp"
#include "core/Finding.hpp"
#include "mcu/Mcu.hpp"
#include "parts/PortType.hpp"
#include "wiring/Net.hpp"

namespace avrbench {

class Part;

// A board file's mistake about one part: "part '<name>': <what>".
inline BadInput part_error(const std::string& part, const std::string& what) {
    return BadInput("part '" + part + "': " + what);
}

// One pin of a part. An Input only listens; an Output drives its net
// push-pull (set_level), through a pull resistor (set_weak), or not at all
// (set_released: an open contact, an open-drain output that is off).
class PartPin final : public Terminal {
public:
    PartPin(Part& part, std::size_t index, std::string name, TerminalRole role)
        : part_(part), index_(index), name_(std::move(name)), role_(role) {}
    std::string label() const override;
    TerminalRole role() const override { return role_; }
    Mcu* clock_mcu() const override;
    Drive drive_state() const override { return drive_; }
    void receive(const Resolution& resolution) override;
    bool begin_wave(const PeriodicWave& wave) override;
    void end_wave(Cycle at) override;

    const std::string& name() const { return name_; }
    // The level the net settled to (what an input reads; 0 while floating).
    bool level() const { return level_; }
    bool connected() const { return net() != nullptr; }
    void set_level(bool level);
    void set_weak(bool level, double ohms);
    void set_released();

private:
    void set_drive(const Drive& drive);

    Part& part_;
    std::size_t index_;
    std::string name_;
    TerminalRole role_;
    Drive drive_;
    bool level_ = false;
};

// A non-digital port. Its kind is the interface the provider offers
// (parts/PortType.hpp); two ports share a net only if their kinds are the same.
struct PortInfo {
    std::string name;
    const PortType* kind = &kAnalogPort;
    bool provides = false;  // offers the kind's interface; else requires it
    bool required = false;  // a requiring port that must be connected
    std::string help;       // what to join it to, for messages and docs
};

// A value a part exposes for tracing (a position, a temperature, a level).
struct PartSignalInfo {
    std::string name;
    bool real = false;  // a real number, else a 0/1 wire
    std::string unit;   // "mm", "deg", "degC", "W", ... ("" for none)
    // What the signal means to the views that show it (the report's plots
    // find signals by it, never by part type): an open vocabulary a part
    // picks from or extends, "" for none. The report's views read
    // "position" (mm or deg: toolpath and velocity), "temperature" and
    // "sensor-temperature" (degC: a thermal plot per part), "heater-on" and
    // "heater-duty" (on the plot of the part in `concerns`), "servo-angle"
    // (deg); others ("heater-power", ...) are for the VCD and front ends.
    std::string role;
    std::string concerns;  // the part this signal is about, when not its own (a heater's plant)
};

class Part {
public:
    Part(std::string name, Mcu& clock) : name_(std::move(name)), clock_(&clock) {}
    virtual ~Part() = default;
    Part(const Part&) = delete;
    Part& operator=(const Part&) = delete;

    const std::string& name() const { return name_; }
    virtual std::string_view type() const = 0;
    Mcu& clock() const { return *clock_; }

    std::size_t pin_count() const { return pins_.size(); }
    PartPin& pin(std::size_t index) { return *pins_[index]; }
    PartPin* find_pin(std::string_view name);

    // Ports (see the file comment). The board calls connect_port once per
    // requiring port with the port of the same kind that provides it; the
    // requirer's connection callback may throw BadInput when the provider
    // does not fit (a channel the provider lacks).
    std::size_t port_count() const { return ports_.size(); }
    const PortInfo& port(std::size_t index) const { return ports_[index]; }
    const PortInfo* find_port(std::string_view name, std::size_t* index = nullptr) const;
    void connect_port(std::size_t port, Part& provider, std::size_t provider_port);
    // An Analog port's voltage at `cycle` of this part's clock.
    double analog_volts(std::size_t port, Cycle cycle) const;

    // After all nets are connected: drive initial outputs, arm timers.
    virtual void start() {}

    const std::vector<Finding>& findings() const { return findings_.all(); }
    // Findings about what is still under way, as they stand if the run ends
    // now (a move the machine has not left yet): not recorded, asked again
    // at each look (Board::findings()).
    virtual std::vector<Finding> pending_findings() const { return {}; }
    // Whether the part is still doing something a run must wait for before
    // the firmware counts as done (a move it accepted and has not made);
    // when it is and `why` is given, one phrase for people there. Asked
    // between slices of a run that waits for idle (Bench::still_going).
    virtual bool still_going(std::string* why) const {
        (void)why;
        return false;
    }

    // The pace of a run that only repeats itself (the fuzz target's steady
    // stepping, bench/fuzz/FirmwareTarget.cpp): mark_pace() starts a window;
    // may_find_more_at_pace(s) says whether going on for `s` more seconds as
    // the part went since the mark (a carriage at the speed it made, a heater
    // heating) could raise a finding it has not raised. A part whose findings
    // come from the timing of its pins alone (a driver's pulse widths, a
    // serial frame) repeats what the window showed: the default, no.
    virtual void mark_pace() {}
    virtual bool may_find_more_at_pace(double seconds) {
        (void)seconds;
        return false;
    }

    // Faults, by name, for tests and scenario files ("open", "stuck_on", ...;
    // "none" repairs). inject_fault applies one when this part's clock reaches
    // `at_cycle` (at the next instruction boundary if that has passed); throws
    // BadInput for a name the part does not know. A part has one fault at a time.
    virtual std::vector<std::string> fault_names() const { return {}; }
    void inject_fault(const std::string& fault, Cycle at_cycle);
    void inject_fault_at_seconds(const std::string& fault, double seconds);
    const std::string& fault() const { return fault_; }
    // Every fault that took effect, with the cycle it did (for reports).
    struct FaultEvent {
        Cycle cycle;
        std::string fault;
    };
    const std::vector<FaultEvent>& fault_history() const { return fault_history_; }

    // Signals for the trace recorder, and a subscription to their changes.
    const std::vector<PartSignalInfo>& signals() const { return signal_infos_; }
    double signal_value(std::size_t signal) const { return signal_values_[signal]; }
    // The signal of that name, if the part has one.
    std::optional<std::size_t> signal_index(std::string_view name) const {
        for (std::size_t i = 0; i < signal_infos_.size(); ++i) {
            if (signal_infos_[i].name == name) return i;
        }
        return std::nullopt;
    }
    // How many times the signal was published since the start (0: never changed).
    std::uint64_t signal_changes(std::size_t signal) const { return signal_changes_[signal]; }
    // The board file's `trace_resolution` (every part type has it): a real
    // signal's value reaches the trace (the listeners) only when it differs
    // from the last one recorded by at least this much (0: every value).
    // signal_value() is always the latest.
    void set_trace_resolution(double step) { trace_resolution_ = step; }
    double trace_resolution() const { return trace_resolution_; }

    // What a user can do to the part from a scenario or Python (press a
    // button, turn a knob): `arguments` numbers each. act() throws BadInput
    // for an action the part does not have or a wrong argument count.
    struct Action {
        std::string name;
        std::size_t arguments;
        std::string help;
    };
    virtual std::vector<Action> actions() const { return {}; }
    virtual void act(const std::string& action, const std::vector<double>& arguments);

    // Values a front end may read at any time that are not traced signals
    // (an axis's step count): Python's part attributes, beside the signals.
    struct Readout {
        std::string name;
        std::function<double()> value;
    };
    const std::vector<Readout>& readouts() const { return readouts_; }
    const Readout* find_readout(std::string_view name) const {
        for (const auto& r : readouts_) {
            if (r.name == name) return &r;
        }
        return nullptr;
    }
    // Text a part shows (an LCD's lines): one string per line.
    struct TextReadout {
        std::string name;
        std::function<std::vector<std::string>()> lines;
    };
    const std::vector<TextReadout>& text_readouts() const { return text_readouts_; }
    // What the part showed over time (an LCD's screens), oldest first: the
    // cycle of each and its lines. Empty for parts that show nothing.
    struct TextScreen {
        Cycle cycle;
        std::vector<std::string> lines;
    };
    virtual std::vector<TextScreen> text_screens() { return {}; }
    const TextReadout* find_text_readout(std::string_view name) const {
        for (const auto& t : text_readouts_) {
            if (t.name == name) return &t;
        }
        return nullptr;
    }

    // One line about the part's state for the run summary ("" for none);
    // not const: a model may first catch up with the clock.
    virtual std::string summary() { return {}; }
    // Called whenever the firmware makes this part act on a command (a
    // driver takes a STEP pulse): the bench's idle detection listens to
    // every part without knowing which ones take commands.
    void on_activity(std::function<void()> fn) { activity_listeners_.push_back(std::move(fn)); }
    using SignalListener = std::function<void(std::size_t signal, Cycle cycle, double value)>;
    void watch_signals(SignalListener fn) { signal_listeners_.push_back(std::move(fn)); }

protected:
    std::size_t add_pin(std::string name, TerminalRole role);
    // Offers `impl` (this part, or a member of it) as port `name` of the
    // kind Interface::kPort.
    template <class Interface>
    std::size_t provide_port(std::string name, Interface& impl, std::string help) {
        return add_port({std::move(name), &Interface::kPort, true, false, std::move(help)}, static_cast<void*>(&impl), {});
    }
    // Needs an Interface on port `name`; `on_connect(Interface&)` or
    // `on_connect(Interface&, Part& provider)` runs when the board joins it.
    template <class Interface, class OnConnect>
    std::size_t require_port(std::string name, bool required, std::string help, OnConnect on_connect) {
        auto connect = [fn = std::move(on_connect)](void* impl, Part& provider) mutable {
            Interface& offered = *static_cast<Interface*>(impl);
            if constexpr (std::is_invocable_v<OnConnect&, Interface&, Part&>) {
                fn(offered, provider);
            } else {
                (void)provider;
                fn(offered);
            }
        };
        return add_port({std::move(name), &Interface::kPort, false, required, std::move(help)}, nullptr, std::move(connect));
    }
    std::size_t provide_analog(std::string name, std::function<double(Cycle)> volts, std::string help);
    std::size_t add_signal(std::string name, bool real, double initial = 0);
    std::size_t add_signal(PartSignalInfo info, double initial);
    void add_readout(std::string name, std::function<double()> value) { readouts_.push_back({std::move(name), std::move(value)}); }
    void add_text_readout(std::string name, std::function<std::vector<std::string>()> lines) {
        text_readouts_.push_back({std::move(name), std::move(lines)});
    }
    void publish(std::size_t signal, double value);

    // Called when an injected fault takes effect ("none": repaired).
    virtual void apply_fault(const std::string& fault) { (void)fault; }

    // A net drove one of this part's input pins.
    virtual void on_input(std::size_t pin, bool level) {
        (void)pin;
        (void)level;
    }
    // A periodic wave arrives on input `pin` in place of its edges
    // (periph/timer/PeriodicOutput.hpp); false refuses. Until end_input_wave,
    // input_level(pin) keeps the wave's start level.
    virtual bool begin_input_wave(std::size_t pin, const PeriodicWave& wave) {
        (void)pin;
        (void)wave;
        return false;
    }
    virtual void end_input_wave(std::size_t pin, Cycle at) {
        (void)pin;
        (void)at;
    }
    // Somebody (the trace recorder) records this part's signals.
    bool signals_watched() const { return !signal_listeners_.empty(); }
    void drive_output(std::size_t pin, bool level) { pins_[pin]->set_level(level); }
    void pull_output(std::size_t pin, bool level, double ohms) { pins_[pin]->set_weak(level, ohms); }
    void release_output(std::size_t pin) { pins_[pin]->set_released(); }
    bool input_level(std::size_t pin) const { return pins_[pin]->level(); }
    bool connected(std::size_t pin) const { return pins_[pin]->connected(); }

    // Records a finding now; returns its index among this part's findings.
    std::size_t report(FindingKind kind, std::string detail);
    // A finding recorded when a fault began, told in full once it is over
    // (a path deviation's worst distance): only its text changes.
    void revise_finding(std::size_t index, std::string detail) { findings_.revise(index).detail = std::move(detail); }
    void note_activity() {
        for (auto& fn : activity_listeners_) fn();
    }

private:
    friend class PartPin;
    std::string name_;
    Mcu* clock_;
    std::vector<std::unique_ptr<PartPin>> pins_;
    std::size_t add_port(PortInfo info, void* offered, std::function<void(void*, Part&)> connect);

    std::vector<PortInfo> ports_;
    std::vector<void*> offered_;                               // per port; the interface a provider offers
    std::vector<std::function<void(void*, Part&)>> connect_;  // per port; a requirer's callback
    std::vector<std::function<double(Cycle)>> analog_sources_;  // per port; empty but for Analog providers
    FindingLog<Finding> findings_;
    std::vector<PartSignalInfo> signal_infos_;
    std::vector<Readout> readouts_;
    std::vector<TextReadout> text_readouts_;
    std::vector<double> signal_values_;
    std::vector<std::uint64_t> signal_changes_;
    double trace_resolution_ = 0;
    std::vector<double> traced_values_;  // what the listeners were last told, per signal
    std::vector<SignalListener> signal_listeners_;
    std::vector<std::function<void()>> activity_listeners_;
    std::string fault_ = "none";
    std::vector<FaultEvent> fault_history_;
};

}  // namespace avrbench
