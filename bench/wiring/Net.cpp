#include "wiring/Net.hpp"

namespace avrbench {

void Terminal::drive(bool level) {
    if (net_ != nullptr) net_->drive_from(this, level);
}

void Terminal::release_net() {
    if (net_ != nullptr) net_->release_from(this);
}

void Net::connect(Terminal& terminal) {
    terminal.net_ = this;
    terminals_.push_back(&terminal);
}

void Net::settle() {
    const Terminal* source = nullptr;
    for (const Terminal* t : terminals_) {
        if (t->role() == TerminalRole::Output && !t->initially_released()) source = t;
    }
    if (source == nullptr) {
        for (const Terminal* t : terminals_) {
            if (t->role() == TerminalRole::Bidirectional) {
                source = t;
                break;
            }
        }
    }
    if (source == nullptr) {
        for (Terminal* t : terminals_) {
            if (t->role() == TerminalRole::Output) release_from(t);
        }
        return;
    }
    drive_from(const_cast<Terminal*>(source), source->initial_level());
}

void Net::release_from(Terminal* source) {
    if (delivering_) return;
    delivering_ = true;
    for (Terminal* t : terminals_) {
        if (t != source) t->receive_release();
    }
    delivering_ = false;
}

void Net::drive_from(Terminal* source, bool level) {
    if (delivering_) return;  // the echo of our own delivery through simavr
    delivering_ = true;
    level_ = level;
    for (Terminal* t : terminals_) {
        if (t != source) t->receive(level);
    }
    delivering_ = false;
}

McuPinTerminal::McuPinTerminal(Mcu& mcu, Pin& pin) : mcu_(mcu), pin_(pin) {
    pin_.on_change([this](Cycle, bool level) { drive(level); });
}

}  // namespace avrbench
