// Helpers shared by the peripheral fixes: simavr's interrupt table, the few
// per-part facts the fixes need (datasheet values), and where a fix's state is
// found from simavr callbacks that carry no parameter.
#pragma once

#include <cstdint>
#include <stdexcept>

extern "C" {
#include <sim_avr.h>
#include <sim_interrupts.h>
}

#include "core/AvrContext.hpp"

namespace avrbench {

// What differs between the parts the fixes know. Values from the datasheets:
// ATmega328P = Atmel-8271 (ATmega48A/PA/88A/PA/168A/PA/328/P), ATmega2560 =
// Atmel-2549 (ATmega640/1280/1281/2560/2561), ATmega32 = Atmel-2503.
struct PartFacts {
    // §7.7.1 (328P, m32) / §7.8.1 (2560): the interrupt response takes 4
    // cycles with a 2-byte PC, 5 with a 3-byte PC; waking from sleep adds as
    // many again; RETI takes as many.
    int response_cycles = 4;
    // Sleep Mode Control: SMCR (0x53) SE bit 0, SM2:0 bits 3:1 on the 328P
    // and 2560 (§10.11.1 / §11.10.1); MCUCR (0x55) SE bit 7, SM2:0 bits 6:4
    // on the ATmega32. 0 = unknown part: sleep fixes stay off.
    avr_io_addr_t sleep_register = 0;
    std::uint8_t se_mask = 0;
    std::uint8_t sm_shift = 0;
    // §14.2.2 (328P) / §13.2.2 (2560): writing a one to PINxn toggles PORTxn.
    // The older ATmega32 has read-only PIN registers.
    bool pin_write_toggles = true;
    // §8.5 (328P) "unlike most other AVRs, the CBI and SBI instructions will
    // only operate on the specified bit" (same on the 2560); the ATmega32's
    // SBI/CBI read-modify-write the whole register.
    bool sbi_single_bit = true;
    // INTn lines whose edge detection needs clk_IO (§13 / §15: INT0/1 on the
    // 328P and m32, INT7:4 on the 2560); the others are asynchronous.
    std::uint8_t synchronous_int_mask = 0x03;
    // EEPROM programming time, in microseconds, for EEPM = 00/01/10 (328P
    // Table 8-2, 2560 Table 8-1: 3.4 ms, 1.8 ms, 1.8 ms); the ATmega32 has no
    // EEPM bits: 8448 cycles of the 1 MHz calibrated RC oscillator (Table 1).
    std::uint32_t eeprom_write_us[3] = {3400, 1800, 1800};
    // ATmega8/16/32/64/128/162/8515/8535: the older register set (MCUCR
    // sleep bits, read-only PINx, the 1 MHz watchdog oscillator).
    bool old_mega = false;
    // PUD, "pull-up disable" (§14.4.1 328P / §13.4.1 2560: MCUCR 0x55 bit 4;
    // ATmega32: SFIOR 0x50 bit 2). 0 = unknown part.
    avr_io_addr_t pud_register = 0;
    std::uint8_t pud_mask = 0;
    bool known = false;
};

PartFacts part_facts(const avr_t* avr);

// Sleep modes (SM2:0, identical on the three parts: §10.1 Table 10-1).
enum SleepMode : std::uint8_t {
    kSleepIdle = 0,
    kSleepAdcNoiseReduction = 1,
    kSleepPowerDown = 2,
    kSleepPowerSave = 3,
    kSleepStandby = 6,
    kSleepExtendedStandby = 7,
};
// The mode currently selected in the sleep register (whether SE is set or not).
std::uint8_t sleep_mode(const avr_t* avr, const PartFacts& facts);
// The oscillator start-up time, in CPU cycles, when waking from `mode`
// (§9.2, §10.5..10.8): none from Idle and ADC Noise Reduction (the clock keeps
// running), 6 cycles from Standby, and from Power-down/Power-save the start-up
// time the CKSEL/SUT fuses select (the ELF's .fuse section; without one the
// Arduino UNO/Mega fuses, low fuse 0xFF: 16K CK).
std::uint32_t wakeup_startup_cycles(const avr_t* avr, std::uint8_t mode);

// simavr stopped the core (cpu_Done) at a SLEEP with interrupts off, but SE
// is clear: on the part that SLEEP does nothing (§10.1); the caller resumes.
bool sleep_was_a_nop(const avr_t* avr);

// The interrupt vector with this number, or nullptr.
avr_int_vector_t* find_vector(avr_t* avr, int number);
// Takes `vector` out of simavr's pending FIFO (its flag is left alone). simavr
// only clears `pending` and leaves the FIFO entry; entries pile up while
// interrupts are off and the 64-entry FIFO silently drops the overflow.
void unpend_interrupt(avr_t* avr, avr_int_vector_t* vector);
// For every vector whose enable bit lives in the register at data address
// `reg`: an enabled vector whose flag is already set becomes pending (§7.7:
// a flag set while the interrupt was disabled is remembered until it is
// enabled); a disabled one stops being pending.
void sync_enables(avr_t* avr, avr_io_addr_t reg);
// The opcode of the instruction at byte address `pc`.
inline unsigned opcode_at(const avr_t* avr, std::uint32_t pc) {
    return avr->flash[pc] | (avr->flash[pc + 1] << 8);
}
// The value an instruction that is writing `value` to I/O data address `addr`
// really writes where SBI/CBI act on a single bit: SBI A,b writes only bit b
// as one, CBI A,b writes nothing (§8.5 on the 328P/2560); otherwise `value`.
std::uint8_t single_bit_write_value(const avr_t* avr, avr_io_addr_t addr, std::uint8_t value);

// Fixes that act when the core enters a sleep mode (the ADC starts a
// conversion in ADC Noise Reduction mode). A listener returns the cycle of the
// earliest event it armed (or 0): the sleep jump must not pass it.
using SleepEntryListener = avr_cycle_count_t (*)(void* context, avr_t* avr, std::uint8_t mode);
void add_sleep_entry_listener(avr_t* avr, SleepEntryListener fn, void* context);
void remove_sleep_entry_listener(avr_t* avr, void* context);
// Called by the sleep callback once per sleep; returns the earliest event
// armed by a listener, 0 if none.
avr_cycle_count_t notify_sleep_entry(avr_t* avr, std::uint8_t mode);

// A fix's state, found from a simavr callback that carries no parameter of
// its own (a module's reset hook gets only its avr_io_t, avr->sleep only the
// avr_t): kept in the AvrContext of the core the key belongs to.
template <typename Value>
struct FixState {
    static void add(const avr_io_t* io, Value* value) { context(io->avr).template add<Value>(io, value); }
    static void add(const avr_t* avr, Value* value) { context(avr).template add<Value>(avr, value); }
    static void remove(const avr_io_t* io) { context(io->avr).template remove<Value>(io); }
    static void remove(const avr_t* avr) { context(avr).template remove<Value>(avr); }
    static Value* find(const avr_io_t* io) { return AvrContext::find_in<Value>(io->avr, io); }
    static Value* find(const avr_t* avr) { return AvrContext::find_in<Value>(avr, avr); }

private:
    static AvrContext& context(const avr_t* avr) {
        AvrContext* c = AvrContext::of(avr);
        if (c == nullptr) throw std::logic_error("a simavr fix on a core without its AvrContext");
        return *c;
    }
};

}  // namespace avrbench
