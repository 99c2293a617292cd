#include "wiring/McuPinTerminal.hpp"

extern "C" {
#include <avr_ioport.h>
#include <sim_avr.h>
}

#include "core/IoHook.hpp"

namespace avrbench {

McuPinTerminal::McuPinTerminal(Mcu& mcu, Pin& pin) : mcu_(mcu), pin_(pin), level_(pin.level()), drive_(drive_state()) {
    // A level change of an output (PORT write, compare output, reset) re-resolves
    // the net. simavr stores an IRQ's new value only after its listeners ran,
    // so the level comes from the notification, not from the pin.
    pin_.on_change([this](Cycle, bool level) {
        level_ = level;
        refresh();
    });
}

McuPinTerminal::~McuPinTerminal() {
    if (registered_as_sink_) mcu_.set_periodic_output_sink(pin_, nullptr);
}

void McuPinTerminal::register_as_sink() { registered_as_sink_ = mcu_.set_periodic_output_sink(pin_, this); }

void McuPinTerminal::unregister_as_sink() {
    if (registered_as_sink_) mcu_.set_periodic_output_sink(pin_, nullptr);
    registered_as_sink_ = false;
}

bool McuPinTerminal::begin_wave(const PeriodicWave& wave) {
    // Only this terminal listens on the pin; every other terminal of the net
    // follows the wave, on this clock.
    if (pin_.listener_count() != 1 || net() == nullptr) return false;
    const auto& terminals = net()->terminals();
    for (const Terminal* t : terminals) {
        if (t != this && t->clock_mcu() != &mcu_) return false;
    }
    for (std::size_t i = 0; i < terminals.size(); ++i) {
        if (terminals[i] == this || terminals[i]->begin_wave(wave)) continue;
        for (std::size_t j = 0; j < i; ++j) {
            if (terminals[j] != this) terminals[j]->end_wave(wave.start);
        }
        return false;
    }
    return true;
}

void McuPinTerminal::end_wave(Cycle at) {
    for (Terminal* t : net()->terminals()) {
        if (t != this) t->end_wave(at);
    }
}

void McuPinTerminal::refresh() {
    const Drive now = drive_state();
    if (now == drive_) return;
    drive_ = now;
    drive_changed();
}

Drive McuPinTerminal::drive_state() const {
    if (pin_.is_output()) return Drive::strong(level_);
    if (pin_.internal_pull_up()) return Drive::weak(true, kInternalPullUpOhm);
    return Drive::none();
}

void McuPinTerminal::receive(const Resolution& resolution) {
    if (pin_.is_output()) {
        // The output buffer sets PINxn; the net's level is not the pin's to read.
        if (pin_.driven()) pin_.release();
        return;
    }
    pin_.drive(resolution.level);
}

McuPortWatch::McuPortWatch(Mcu& mcu) : mcu_(mcu) {
    if (const std::uint16_t pud = mcu.pud_register(); pud != 0) {
        write_hooks_.push_back(std::make_unique<IoWriteHook>(mcu.avr(), pud, &on_pud_write, this));
    }
    mcu.on_reset([this] { refresh_all(); });
    direction_listener_ = mcu.on_pin_direction_change([this] { refresh_all(); });
}

McuPortWatch::~McuPortWatch() {
    mcu_.remove_pin_direction_listener(direction_listener_);
    // Hooks chain on simavr's I/O slots: undo them newest first.
    while (!read_hooks_.empty()) read_hooks_.pop_back();
    while (!write_hooks_.empty()) write_hooks_.pop_back();
}

void McuPortWatch::add(McuPinTerminal& terminal) {
    avr_ioport_t* port = terminal.pin().port();
    auto& slot = ports_[port];
    if (!slot) {
        slot = std::make_unique<PortWatch>();
        slot->owner = this;
        slot->port = port;
        avr_t* avr = mcu_.avr();
        for (avr_io_addr_t reg : {port->r_port, port->r_ddr, port->r_pin}) {
            write_hooks_.push_back(std::make_unique<IoWriteHook>(avr, reg, &on_write, slot.get()));
        }
        read_hooks_.push_back(std::make_unique<IoReadHook>(avr, port->r_pin, &on_pin_read, slot.get()));
    }
    slot->terminals.push_back(&terminal);
}

void McuPortWatch::on_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    hook.write_original(avr, addr, value);
    for (McuPinTerminal* t : static_cast<PortWatch*>(hook.context())->terminals) t->refresh();
}

void McuPortWatch::on_pud_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    hook.write_original(avr, addr, value);
    static_cast<McuPortWatch*>(hook.context())->refresh_all();
}

namespace {

unsigned word_at(const avr_t* avr, std::uint32_t pc) {
    return pc + 1 <= avr->flashend ? avr->flash[pc] | (avr->flash[pc + 1] << 8) : 0xFFFF;
}

}  // namespace

// Which PINx bits the instruction at `pc` uses (AVR Instruction Set Manual
// encodings). SBI/CBI (1001 10x0 AAAA Abbb) read PINx only to write one bit
// back (a toggle); SBIC/SBIS (1001 10x1 AAAA Abbb) test bit b. IN (1011 0AAd
// dddd AAAA) and LDS (1001 000d dddd 0000, k) load the byte into Rd: when the
// next instruction (after a COM Rd, 1001 010d dddd 0000) masks Rd with ANDI
// (0111 KKKK dddd KKKK) or tests one bit with SBRC/SBRS (1111 11xd dddd 0bbb),
// only those bits are used - a whole-port read for one pin (Prusa-Firmware's
// `lds r24, PINK; com r24; andi r24, 1`) does not read the port's other pins.
// Anything else takes the whole byte.
std::uint8_t pin_bits_used(const avr_t* avr, std::uint32_t pc) {
    const unsigned opcode = word_at(avr, pc);
    if ((opcode & 0xFD00) == 0x9800) return 0;
    if ((opcode & 0xFD00) == 0x9900) return static_cast<std::uint8_t>(1u << (opcode & 0x7));
    unsigned rd = 0;
    std::uint32_t next = 0;
    if ((opcode & 0xF800) == 0xB000) {
        rd = (opcode >> 4) & 0x1F;
        next = pc + 2;
    } else if ((opcode & 0xFE0F) == 0x9000) {
        rd = (opcode >> 4) & 0x1F;
        next = pc + 4;
    } else {
        return 0xFF;
    }
    unsigned op = word_at(avr, next);
    if ((op & 0xFE0F) == 0x9400 && ((op >> 4) & 0x1F) == rd) op = word_at(avr, next + 2);  // COM Rd
    if ((op & 0xF000) == 0x7000 && 16 + ((op >> 4) & 0xF) == rd) {                        // ANDI Rd, K
        return static_cast<std::uint8_t>(((op >> 4) & 0xF0) | (op & 0x0F));
    }
    if ((op & 0xFC08) == 0xFC00 && ((op >> 4) & 0x1F) == rd) return static_cast<std::uint8_t>(1u << (op & 0x7));  // SBRC/SBRS
    return 0xFF;
}

std::uint8_t McuPortWatch::on_pin_read(IoReadHook& hook, avr_t* avr, avr_io_addr_t addr) {
    auto* watch = static_cast<PortWatch*>(hook.context());
    // avr->pc is still the reading instruction's address.
    const std::uint8_t used = pin_bits_used(avr, avr->pc);
    for (McuPinTerminal* t : watch->terminals) {
        if ((used & t->pin().mask()) != 0 && t->net()->resolution().state == NetState::Floating && !t->pin().is_output()) {
            t->net()->floating_read(watch->owner->mcu_, t->label());
        }
    }
    return hook.read_original(avr, addr);
}

void McuPortWatch::refresh_all() {
    for (auto& [port, watch] : ports_) {
        for (McuPinTerminal* t : watch->terminals) t->refresh();
    }
}

}  // namespace avrbench
