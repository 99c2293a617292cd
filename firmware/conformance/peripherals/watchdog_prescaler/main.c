/*
 * watchdog_prescaler - a change of the watchdog's prescaler takes effect
 * (ATmega328P §11.9.2 WDTCSR, §11.8.2; ATmega2560 §12.5.2): "The WDP3..0
 * bits determine the Watchdog Timer prescaling when the Watchdog Timer is
 * running", changed in the timed sequence (WDCE and WDE, then the new value
 * within four cycles); "the Watchdog Timer should be reset before any change
 * of the WDP bits" - avr-libc's wdt_enable() does both.
 *
 * Boot 1: System Reset Mode at 500 ms (WDP = 0101: 64K cycles of 128 kHz),
 * served with WDR for 10 rounds of 16000 cycles, then wdt_enable(WDTO_15MS)
 * (WDR, then WDP = 0000: 2K cycles = 16 ms) and a spin: the reset comes
 * 16 ms after that, not 512 ms. Boot 2 (WDRF): the watchdog off, `boot_count`
 * 2, `reset_flags` MCUSR.
 */
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
    const uint8_t flags = MCUSR;
    MCUSR = 0;
    if (flags & (1 << PORF)) boot_count = 0;
    ++boot_count;
    if (boot_count > 1) {
        reset_flags = flags;
        wdt_disable();
        for (;;) {
        }
    }
    wdt_enable(WDTO_500MS);
    for (uint8_t i = 0; i < 10; ++i) {
        _delay_loop_2(4000); /* 16000 cycles */
        wdt_reset();
    }
    wdt_enable(WDTO_15MS);
    for (;;) {
    }
}
