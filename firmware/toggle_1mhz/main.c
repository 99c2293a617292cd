/*
 * toggle_1mhz - PB0 changes level once every microsecond (16 cycles at
 * 16 MHz), forever: one million recorded edges per simulated second, the
 * workload of the bounded-memory benchmark (docs/PERFORMANCE.md).
 *
 * The loop (ATmega328P instruction set manual): SBI PINB,0 toggles PB0 in
 * 2 cycles (§14.2.2), 12 NOPs take 12, RJMP 2: 16 cycles per edge.
 */
#include <avr/io.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

int main(void)
{
    DDRB = _BV(PB0);
    for (;;) {
        __asm__ __volatile__(
            "1: sbi %[pin], 0\n\t"
            "nop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop\n\t"
            "nop\n\tnop\n\tnop\n\tnop\n\tnop\n\tnop\n\t"
            "rjmp 1b\n\t"
            :
            : [pin] "I"(_SFR_IO_ADDR(PINB)));
    }
}
