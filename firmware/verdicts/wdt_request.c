/*
 * wdt_request - a firmware that resets itself on purpose, the way
 * avr-libc's <avr/wdt.h> documentation, Arduino sketches and Klipper's
 * `reset` command do it: wdt_enable(WDTO_15MS) and spin until the watchdog
 * fires (with WD_SPIN_CLI: interrupts off first, as Klipper's
 * command_reset). The watchdog is served with WDR before (a firmware that
 * uses its watchdog all along), so the request is told by what happens
 * after the last set-up: no WDR, a jump to itself.
 *
 * Boot 1: serve the watchdog (500 ms time-out, WDR every ~1 ms) for 20 ms,
 * then ask for the reset. Boot 2 (WDRF): switch the watchdog off and stay,
 * toggling PB4.
 * Observable: reset_flags (MCUSR at boot), boot_count (.noinit).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/wdt.h>
#include <stdint.h>
#include <util/delay_basic.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t reset_flags;
volatile uint8_t boot_count __attribute__((section(".noinit")));

int main(void)
{
    reset_flags = MCUSR;
    MCUSR = 0;
    if (reset_flags & _BV(PORF)) boot_count = 0;
    boot_count++;
    DDRB = _BV(PB4);
    if (reset_flags & _BV(WDRF)) {
        wdt_disable();
        for (;;) {
            PINB = _BV(PB4);
            _delay_loop_2(4000);
        }
    }
    wdt_enable(WDTO_500MS);
    for (uint8_t ms = 0; ms < 20; ++ms) {
        _delay_loop_2(4000); /* 16000 cycles */
        wdt_reset();
    }
#ifdef WD_SPIN_CLI
    cli();
#endif
    wdt_enable(WDTO_15MS);
    for (;;) {
    }
}
