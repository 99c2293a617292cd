/*
 * watchdog_m32 - the ATmega32's watchdog ("Watchdog Timer", Table 17, WDTCR).
 *
 * "The Watchdog Timer is clocked from a separate On-chip Oscillator which runs
 * at 1 MHz"; WDP2:0 = 000: 16K (16,384) oscillator cycles = 16.384 ms =
 * 262144 cycles at 16 MHz. WDTCR's initial value is 0: after the watchdog
 * reset the watchdog is off until the firmware enables it again.
 *
 * Boot 1 (MCUCSR.PORF): WDTCR = WDE (WDP = 000), then spin without WDR.
 * Boot 2 (MCUCSR.WDRF): store MCUCSR in `reset_flags`, leave the watchdog
 * alone and spin: no further reset. `boot_count` lives in .noinit.
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t reset_flags;
volatile uint8_t boot_count __attribute__((section(".noinit")));

int main(void)
{
    const uint8_t flags = MCUCSR;
    MCUCSR = 0;
    if (flags & (1 << PORF)) boot_count = 0;
    ++boot_count;
    if (boot_count == 1) {
        WDTCR = (1 << WDE); /* WDP2:0 = 000 */
    } else {
        reset_flags = flags;
    }
    for (;;) {
    }
}
