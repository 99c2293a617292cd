// Every correction the bench applies to a simavr core, one per file in this
// folder; SimavrFixes installs them in this order. docs/FIDELITY.md lists each
// with its datasheet section and test.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "periph/Fix.hpp"

struct avr_uart_t;

namespace avrbench {

// simavr performs writes above RAMEND past its data buffer; grow it to 64 KiB.
std::unique_ptr<Fix> install_memory_guard(avr_t* avr);
// SLEEP fast-forwards in simulated time only (no usleep).
std::unique_ptr<Fix> install_virtual_sleep(avr_t* avr);
// USART: no usleep on UCSRnA polls, no stdout echo, datasheet frame length.
std::unique_ptr<Fix> install_uart_framing(avr_t* avr);
// A USART's frame format as its registers set it (ATmega328P §20.4).
struct UartFrame {
    std::uint32_t cycles_per_bit = 16;
    int data_bits = 8;   // 5..9
    int parity = 0;      // UPMn1:0: 0 none, 2 even, 3 odd
    int stop_bits = 1;   // 1 or 2
    int bits() const { return 1 + data_bits + (parity != 0 ? 1 : 0) + stop_bits; }
};
UartFrame uart_frame(avr_t* avr, const avr_uart_t* uart);
// Where UCSRC shares its location with UBRRH (ATmega32: URSEL), the UCSRC the
// firmware last wrote, kept by install_uart_ursel; uart_frame reads it from
// here. nullptr unregisters.
void set_uart_ucsrc_shadow(const avr_uart_t* uart, const std::uint8_t* ucsrc);
// The line level during each bit time of a frame carrying `data` (§20.4,
// Figure 20-4): start bit low, data bits LSB first (the ninth from bit 8),
// the parity bit (even: the ones including it are even; odd: odd; the
// reserved UPM = 01 as even), stop bits high.
struct UartFrameLevels {
    std::array<bool, 13> high{};  // 1 + 9 + 1 + 2 bits at most
    int count = 0;
};
UartFrameLevels uart_frame_levels(const UartFrame& frame, std::uint32_t data);

// --- peripherals: interrupts, ports, sleep, watchdog, ADC, USART, EEPROM
// Pins a peripheral drives in place of PORTxn (timers' OCnx, USARTs' TxDn):
// CompareOutputPins, installed before the fixes that add drivers to it.
std::unique_ptr<Fix> install_port_overrides(avr_t* avr);
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
// SPI master: a byte takes 8 SCK periods at the SPR/SPI2X clock (simavr:
// 100 us whatever the clock); SPDR written during a transfer sets WCOL.
std::unique_ptr<Fix> install_spi_timing(avr_t* avr);
// SPI master: an input SS driven low makes it a slave (MSTR cleared, SPIF
// set, the interrupt); simavr ignores SS.
std::unique_ptr<Fix> install_spi_slave_select(avr_t* avr);
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
