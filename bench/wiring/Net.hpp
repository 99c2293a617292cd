// Nets join terminals: MCU pins and part pins (and pins of several MCUs).
// Every terminal says what it puts on the net (wiring/Drive.hpp: nothing, a
// pull resistor, a push-pull level); the net resolves them the way a logic
// input reads the wire and delivers the result to every terminal. Two strong
// drivers that disagree are a finding (net-contention), and so is firmware
// reading a floating net (floating-input-read, reported by the MCU side).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/Finding.hpp"
#include "mcu/Mcu.hpp"
#include "periph/timer/PeriodicOutput.hpp"
#include "wiring/Drive.hpp"

namespace avrbench {

class Net;

enum class TerminalRole {
    Input,          // only listens (a driver's STEP input)
    Output,         // drives or lets go (a switch contact, a push-pull output, a pull resistor)
    Bidirectional,  // an MCU pin: input or output as its DDR says
};

class Terminal {
public:
    virtual ~Terminal() = default;
    virtual std::string label() const = 0;  // "uno.PD2", "x_driver.step"
    virtual TerminalRole role() const = 0;
    // The MCU whose clock the terminal lives on (its own, or its part's), if any.
    virtual Mcu* clock_mcu() const { return nullptr; }
    // The MCU pin this terminal is (of clock_mcu()), nullptr for a part's pin.
    virtual Pin* mcu_pin() const { return nullptr; }
    // What the terminal puts on the net now.
    virtual Drive drive_state() const = 0;
    // The net settled to `resolution` (delivered to every terminal, the
    // drivers included, whenever the resolution changes).
    virtual void receive(const Resolution& resolution) = 0;
    // An MCU pin on the net repeats a periodic wave (periph/timer/PeriodicOutput.hpp)
    // instead of delivering its edges; true if this terminal follows it. The
    // net's resolution keeps the wave's start level meanwhile.
    virtual bool begin_wave(const PeriodicWave& wave) {
        (void)wave;
        return false;
    }
    // The wave ended at period boundary `at` (the clock shows `at`).
    virtual void end_wave(Cycle at) { (void)at; }

    Net* net() const { return net_; }

protected:
    // The terminal's drive changed: the net resolves again.
    void drive_changed();

private:
    friend class Net;
    Net* net_ = nullptr;
};

class Net {
public:
    // What this one finds (`avrbench findings` lists every kind).
    static const FindingKind kNetContention;  // net-contention
    static const FindingKind kFloatingInputRead;  // floating-input-read
    explicit Net(std::string name) : name_(std::move(name)) {}
    Net(const Net&) = delete;
    Net& operator=(const Net&) = delete;

    const std::string& name() const { return name_; }
    void connect(Terminal& terminal);
    const std::vector<Terminal*>& terminals() const { return terminals_; }
    // The MCU whose cycle counter stamps this net's findings.
    void set_clock(Mcu& mcu) { clock_ = &mcu; }

    // First resolution, delivered to every terminal. Called once all terminals are connected.
    void settle();
    // Re-resolves after a terminal's drive changed; delivers only a change.
    void update();

    const Resolution& resolution() const { return resolution_; }
    bool level() const { return resolution_.level; }

    // `reader`'s firmware read this net's pin `pin_label` while the net floats.
    // One finding per floating spell, and only when something else on the net
    // could drive it (a net of the MCU's own outputs is not read as a signal).
    void floating_read(Mcu& reader, const std::string& pin_label);
    const std::vector<Finding>& findings() const { return findings_.all(); }

private:
    void deliver();
    std::string drivers_text() const;

    std::string name_;
    std::vector<Terminal*> terminals_;
    std::vector<Drive> drives_;  // scratch, one per terminal
    Resolution resolution_;
    bool settled_ = false;
    bool delivering_ = false;
    bool update_pending_ = false;
    bool floating_read_reported_ = false;
    Mcu* clock_ = nullptr;
    FindingLog<Finding> findings_;
};

}  // namespace avrbench
