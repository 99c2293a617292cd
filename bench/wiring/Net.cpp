#include "wiring/Net.hpp"

#include <cstdio>

namespace avrbench {

const FindingKind Net::kNetContention = FindingKind::declare("net-contention", "two outputs drive one net to opposite levels", Severity::Warning);
const FindingKind Net::kFloatingInputRead = FindingKind::declare("floating-input-read", "the firmware read an input pin whose net nothing drives", Severity::Warning);

void Terminal::drive_changed() {
    if (net_ != nullptr) net_->update();
}

void Net::connect(Terminal& terminal) {
    terminal.net_ = this;
    terminals_.push_back(&terminal);
    drives_.resize(terminals_.size());
}

void Net::settle() {
    settled_ = true;
    for (std::size_t i = 0; i < terminals_.size(); ++i) drives_[i] = terminals_[i]->drive_state();
    resolution_ = resolve(drives_);
    deliver();
}

void Net::update() {
    if (!settled_) return;
    if (delivering_) {
        // A terminal reacted to our own delivery (simavr echoes a driven MCU
        // pin through its IRQ): resolve again once the delivery is over.
        update_pending_ = true;
        return;
    }
    // A terminal that changes its drive in answer to the level it received
    // (a part with feedback) gets a few rounds; a loop that never settles is
    // an oscillator, which a net without delay cannot represent.
    for (int round = 0; round < 8; ++round) {
        for (std::size_t i = 0; i < terminals_.size(); ++i) drives_[i] = terminals_[i]->drive_state();
        const Resolution next = resolve(drives_);
        if (next == resolution_) return;
        const bool contention_starts = next.state == NetState::Contention && resolution_.state != NetState::Contention;
        if (next.state != NetState::Floating) floating_read_reported_ = false;
        resolution_ = next;
        if (contention_starts && clock_ != nullptr) {
            Finding f;
            f.kind = Net::kNetContention;
            f.source = name_;
            f.cycle = clock_->cycle();
            f.clock_hz = clock_->frequency_hz();
            f.has_pc = false;
            f.detail = "net '" + name_ + "': outputs drive opposite levels (" + drivers_text() + ")";
            findings_.record(std::move(f));
        }
        update_pending_ = false;
        deliver();
        if (!update_pending_) return;
    }
}

void Net::deliver() {
    delivering_ = true;
    for (Terminal* t : terminals_) {
        // Another MCU's pin or part: brought up to the running MCU's time first.
        if (Mcu* clock = t->clock_mcu()) clock->before_external_change();
        t->receive(resolution_);
    }
    delivering_ = false;
}

std::string Net::drivers_text() const {
    std::string out;
    for (std::size_t i = 0; i < terminals_.size(); ++i) {
        if (drives_[i].strength != Strength::Strong) continue;
        if (!out.empty()) out += ", ";
        out += terminals_[i]->label() + (drives_[i].level ? " high" : " low");
    }
    return out;
}

void Net::floating_read(Mcu& reader, const std::string& pin_label) {
    if (resolution_.state != NetState::Floating || floating_read_reported_) return;
    bool something_else_drives = false;
    for (const Terminal* t : terminals_) {
        if (t->label() != pin_label && t->role() != TerminalRole::Input) something_else_drives = true;
    }
    if (!something_else_drives) return;
    floating_read_reported_ = true;
    Finding f;
    f.kind = Net::kFloatingInputRead;
    f.source = name_;
    f.cycle = reader.cycle();
    f.clock_hz = reader.frequency_hz();
    f.pc_bytes = reader.pc_bytes();
    f.symbol = reader.describe_pc(f.pc_bytes);
    char why[96];
    if (resolution_.volts_fraction > 0) {
        std::snprintf(why, sizeof why, "its pull resistors hold it at %.2f VCC, between V_IL and V_IH",
                      resolution_.volts_fraction);
    } else {
        std::snprintf(why, sizeof why, "nothing drives it and no pull-up is on");
    }
    f.detail = "the firmware read " + pin_label + " while net '" + name_ + "' floats (" + why + "); the bench reads 0";
    findings_.record(std::move(f));
}

}  // namespace avrbench
