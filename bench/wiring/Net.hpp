// Nets join terminals: MCU pins and part pins (and pins of several MCUs).
// A terminal that drives the net delivers its level to every other terminal.
// simavr's pin IRQs call back into the net when a part drives an MCU pin; the
// net ignores that echo, so a level travels once around.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/Mcu.hpp"

namespace avrbench {

class Net;

enum class TerminalRole {
    Input,          // only listens (a driver's STEP input)
    Output,         // drives (a switch contact); two on one net is a wiring error
    Bidirectional,  // an MCU pin: input or output as its DDR says
};

class Terminal {
public:
    virtual ~Terminal() = default;
    virtual std::string label() const = 0;  // "uno.PD2", "x_driver.step"
    virtual TerminalRole role() const = 0;
    // A level driven onto the net by another terminal.
    virtual void receive(bool level) = 0;
    // The driving terminal let go of the net (an open switch contact).
    virtual void receive_release() {}
    // An Output that is currently not driving (open contact) does not set the
    // net's level when it is formed.
    virtual bool initially_released() const { return false; }
    // The terminal's own idea of its level when the net is formed.
    virtual bool initial_level() const { return false; }

    Net* net() const { return net_; }

protected:
    // Drives the net (or just remembers the level while unconnected).
    void drive(bool level);
    // Stops driving the net.
    void release_net();

private:
    friend class Net;
    Net* net_ = nullptr;
};

class Net {
public:
    explicit Net(std::string name) : name_(std::move(name)) {}
    Net(const Net&) = delete;
    Net& operator=(const Net&) = delete;

    const std::string& name() const { return name_; }
    void connect(Terminal& terminal);
    const std::vector<Terminal*>& terminals() const { return terminals_; }
    bool level() const { return level_; }

    // Sets the net's level from the terminals' initial levels: a driving
    // Output's, else an MCU pin's. Called once all terminals are connected.
    void settle();

private:
    friend class Terminal;
    void drive_from(Terminal* source, bool level);
    void release_from(Terminal* source);

    std::string name_;
    std::vector<Terminal*> terminals_;
    bool level_ = false;
    bool delivering_ = false;
};

// An MCU pin as a terminal.
class McuPinTerminal final : public Terminal {
public:
    McuPinTerminal(Mcu& mcu, Pin& pin);
    std::string label() const override { return mcu_.name() + "." + pin_.name(); }
    TerminalRole role() const override { return TerminalRole::Bidirectional; }
    void receive(bool level) override { pin_.drive(level); }
    void receive_release() override { pin_.release(); }
    bool initial_level() const override { return pin_.level(); }

    Mcu& mcu() const { return mcu_; }
    Pin& pin() const { return pin_; }

private:
    Mcu& mcu_;
    Pin& pin_;
};

}  // namespace avrbench
