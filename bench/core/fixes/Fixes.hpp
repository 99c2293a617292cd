// Every correction the bench applies to a simavr core, one per file in this
// folder; SimavrFixes installs them in this order. docs/FIDELITY.md lists each
// with its datasheet section and test.
#pragma once

#include <memory>

#include "core/fixes/Fix.hpp"

namespace avrbench {

// simavr performs writes above RAMEND past its data buffer; grow it to 64 KiB.
std::unique_ptr<Fix> install_memory_guard(avr_t* avr);
// SLEEP fast-forwards in simulated time only (no usleep).
std::unique_ptr<Fix> install_virtual_sleep(avr_t* avr);
// USART: no usleep on UCSRnA polls, no stdout echo, datasheet frame length.
std::unique_ptr<Fix> install_uart_framing(avr_t* avr);

// --- peripherals: interrupts, ports, sleep, watchdog, ADC, USART, EEPROM
// Interrupt response 4/5 cycles, one instruction after RETI/SEI, exact
// wake-up from SLEEP (+ response + start-up time), SLEEP with SE = 0 is a NOP.
std::unique_ptr<Fix> install_interrupt_timing(avr_t* avr);
// INTn edge/level without per-cycle polling; INTFn/PCIFn write-one-to-clear;
// enabling with the flag set interrupts.
std::unique_ptr<Fix> install_external_interrupts(avr_t* avr);
// SBI PINx,n toggles bit n only; read-only PINx on the ATmega32; pins
// tri-state at a reset.
std::unique_ptr<Fix> install_port_pins(avr_t* avr);
// Watchdog Interrupt Mode keeps WDIE; WDIF write-one-to-clear; the older
// megas' 1 MHz watchdog oscillator and WDTCR = 0 after a reset.
std::unique_ptr<Fix> install_watchdog(avr_t* avr);
// ADC: conversion timing from the ADC clock edges (25/13/13.5 clocks), channel
// latched at the start and sampled at sample-and-hold, all auto-trigger
// sources, ADIF write-one-to-clear, data-register lock, ADC8..15 inputs kept
// (simavr drops them).
std::unique_ptr<Fix> install_adc_conversion(avr_t* avr);
// USART transmitter: double-buffered UDR (bytes exactly one frame apart),
// TXC at the end of the last frame, UDRE a level interrupt.
std::unique_ptr<Fix> install_uart_transmitter(avr_t* avr);
// ATmega32-style USART: UCSRC and UBRRH share an address (URSEL selects).
std::unique_ptr<Fix> install_uart_ursel(avr_t* avr);
// EEPROM: EEPE stays set for the programming time (EEPM modes), CPU halts
// after EEPE/EERE, EE_READY is a level interrupt.
std::unique_ptr<Fix> install_eeprom_timing(avr_t* avr);
// SPM only from the boot loader section (BOOTSZ fuses); elsewhere a no-op.
std::unique_ptr<Fix> install_self_programming(avr_t* avr);

// --- timers
// TIFRn write-one-to-clear by OUT/STS and by SBI (one bit); enabling TIMSKn
// with the flag already set interrupts.
std::unique_ptr<Fix> install_timer_flags(avr_t* avr);
// Timer/Counters 0..5 from the datasheets (counting, compare matches, all
// WGM modes, OCnx pins overriding PORTxn, input capture, prescalers) in place
// of simavr's avr_timer handlers, on the megaAVRs it knows.
std::unique_ptr<Fix> install_timer_model(avr_t* avr);
// Timer events of a steady period are replayed from a record of one period
// (TimerModel.cpp); on by default. Off only to compare (TimerReplay.*).
void set_timer_replay(bool on);

}  // namespace avrbench
