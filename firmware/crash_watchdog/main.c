/*
 * crash_watchdog - lets the watchdog reset the MCU once, then stays alive.
 *
 * First boot (not a watchdog reset): enable the watchdog in System Reset
 * Mode with the shortest time-out, serve it with WDR five times about 1 ms
 * apart, then hang: spin without ever executing WDR again (a firmware that
 * stops serving its watchdog, not one asking for a reset: that is
 * firmware/verdicts/wdt_request). The
 * watchdog oscillator runs at 128 kHz; WDP3:0 = 0000 is 2K (2048) of its
 * cycles = 16 ms typical (avr-libc calls it WDTO_15MS), i.e. 256000 CPU
 * cycles at 16 MHz - which is also how simavr 1.6 models it
 * (2048 << WDP) * F_CPU / 128000. The datasheet warns the oscillator is
 * voltage and temperature dependent; 16 ms is the nominal figure.
 *
 * Second boot (watchdog reset, WDRF set in MCUSR): clear WDRF and switch
 * the watchdog off with the timed sequence, then stay in a loop toggling PB4
 * (UNO D12) about every 16000 cycles (~1 ms). Nothing resets the MCU again.
 *
 * Observable:
 *   reset_flags  MCUSR as read at the start of the current boot
 *                (0x01 PORF on the first, 0x08 WDRF after the watchdog reset)
 *   boot_count   1 after power-on, 2 after the watchdog reset (in .noinit,
 *                so the C start-up code does not clear it on the reset)
 *   PB5          toggled once at the start of every boot (high, since a
 *                reset clears PORTB)
 *   PB4          toggling only after the watchdog reset
 */
#include <avr/io.h>
#include <avr/wdt.h>
#include <stdint.h>
#include <util/delay_basic.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

/* Globals, non-static: the bench reads them by symbol. volatile because
 * nothing in the program reads them back, and GCC otherwise drops the
 * stores in a main() that never returns. */
volatile uint8_t reset_flags;
volatile uint8_t boot_count __attribute__((section(".noinit")));

int main(void)
{
    /* Read MCUSR before anything else. With WDRF set, the watchdog is still
     * enabled (WDE is forced on while WDRF is set) at the shortest time-out,
     * so the code up to wdt_disable() must take well under 16 ms. */
    reset_flags = MCUSR;
    /* The flags are only cleared by a power-on reset or by writing zero;
     * clear them so the next boot sees only the cause of *its* reset. WDRF
     * must be cleared before WDE can be cleared ("Watchdog Timer"). */
    MCUSR = 0;

    if (reset_flags & _BV(PORF)) {
        boot_count = 0; /* SRAM content is undefined after power-on */
    }
    boot_count++;

    DDRB = _BV(PB5) | _BV(PB4);
    PINB = _BV(PB5); /* the one start-up toggle (per boot) */

    if (reset_flags & _BV(WDRF)) {
        /* Timed sequence: write WDCE and WDE together, then within four
         * cycles write WDE = 0 (and the new prescaler). avr-libc's
         * wdt_disable() does exactly that with interrupts off. */
        wdt_disable();
        for (;;) {
            PINB = _BV(PB4);
            _delay_loop_2(4000); /* 4 cycles per count: 16000 cycles */
        }
    }

    /* WDE = 1, WDIE = 0 -> System Reset Mode; WDP3:0 = 0000 -> 2K cycles of
     * the 128 kHz oscillator (16 ms). Changing WDE/WDP needs the same timed
     * WDCE sequence, done by wdt_enable(). */
    wdt_enable(WDTO_15MS);
    for (uint8_t served = 0; served < 5; ++served) {
        _delay_loop_2(4000); /* 16000 cycles */
        wdt_reset();
    }
    for (;;) {
        /* Hung: deliberately no wdt_reset() any more. */
    }
}
