/*
 * wdt_hang - a firmware whose watchdog fires because it hung before its
 * first WDR: it enables the watchdog (15 ms) at boot and then waits in a
 * loop for a flag nothing ever sets (a polling loop, not a jump to itself).
 * Boot 2 (WDRF): switch the watchdog off and stay.
 */
#include <avr/io.h>
#include <avr/wdt.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t reset_flags;
volatile uint8_t ready;

int main(void)
{
    reset_flags = MCUSR;
    MCUSR = 0;
    if (reset_flags & _BV(WDRF)) {
        wdt_disable();
        for (;;) {
        }
    }
    wdt_enable(WDTO_15MS);
    while (!ready) {
        /* waits for an interrupt that is never enabled */
    }
    for (;;) {
        wdt_reset();
    }
}
