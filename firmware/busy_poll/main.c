/*
 * busy_poll - CPU-bound polling loop (no interrupts, no sleep, no delay).
 *
 * The workload of the performance benchmark: every simulated cycle executes
 * an instruction and the program touches an input port, SRAM and an output
 * port, like the main loop of a polling firmware.
 *
 * Each iteration reads PINB and adds it into the 16-bit `pinb_sum` (in SRAM,
 * volatile so the work cannot be optimised away) and counts the iteration;
 * every 64th iteration it increments `portd_count` and writes it to PORTD.
 * So PD0 toggles every 64 iterations, PD1 every 128, ... PD7 every 8192:
 * PORTD is a binary counter of 64-iteration blocks. The cycle count of one
 * iteration is fixed by the generated code; see README.md.
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

/* Global so the bench can read them from the ELF's symbol table. */
volatile uint16_t pinb_sum;
volatile uint8_t portd_count;

int main(void)
{
    DDRD = 0xFF; /* PD0..PD7 all outputs (PD0/PD1 double as RXD/TXD, unused) */

    uint8_t iteration = 0;
    for (;;) {
        pinb_sum += PINB;
        if ((++iteration & 63u) == 0) {
            PORTD = ++portd_count;
        }
    }
}
