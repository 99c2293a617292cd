/*
 * watchdog_modes - the watchdog's Interrupt Mode and Interrupt and System
 * Reset Mode (ATmega328P §11.8.2 Table 11-1 and §11.9.2 WDTCSR; ATmega2560
 * §12.4.2 Table 12-1, §12.5.2).
 *
 * WDP3:0 = 0000: 2K cycles of the 128 kHz watchdog oscillator = 16 ms
 * (Table 11-2) = 256000 cycles at 16 MHz.
 *
 * Default build (Interrupt Mode, WDE = 0, WDIE = 1): "the Watchdog Interrupt
 * ... generates an interrupt" at every time-out; WDIE stays set. The ISR
 * counts into `wdt_interrupts` and toggles PB0 (by writing PORTB).
 *
 * -DINT_AND_RESET (WDE = 1, WDIE = 1): "The first time-out in the Watchdog
 * Timer will set WDIF. Executing the corresponding interrupt vector will
 * clear WDIE and WDIF automatically by hardware (the Watchdog goes to System
 * Reset Mode)"; the next time-out resets the part. `boot_count` (.noinit)
 * counts boots; PB5 is driven high at every boot: the reset tri-states it
 * (§11.1: "The I/O ports of the AVR are immediately reset to their initial
 * state when a reset source goes active"). After the reset the firmware
 * stores MCUSR in `reset_flags` and turns the watchdog off.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/wdt.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t wdt_interrupts;
volatile uint8_t reset_flags;
volatile uint8_t boot_count __attribute__((section(".noinit")));

ISR(WDT_vect)
{
    ++wdt_interrupts;
    PORTB ^= (1 << PB0);
}

int main(void)
{
    const uint8_t flags = MCUSR;
    MCUSR = 0;
    if (flags & (1 << PORF)) boot_count = 0;
    ++boot_count;
    DDRB = (1 << PB0) | (1 << PB5);
    PORTB = (1 << PB5);
    if (boot_count > 1) {
        reset_flags = flags;
        wdt_disable();
        for (;;) {
        }
    }
    cli();
    wdt_reset();
#ifdef INT_AND_RESET
    WDTCSR = (1 << WDCE) | (1 << WDE);
    WDTCSR = (1 << WDIE) | (1 << WDE); /* WDP = 0: 16 ms */
#else
    WDTCSR = (1 << WDCE) | (1 << WDE);
    WDTCSR = (1 << WDIE); /* WDP = 0: 16 ms */
#endif
    sei();
    for (;;) {
    }
}
