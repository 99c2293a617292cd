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
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
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
#ifdef BUSY_POLL_PASSES
    /* busy_poll_passes: a fixed amount of the same work, then the end
     * (below), so every simulator in bench/perf (the bench, bare simavr,
     * qemu) runs the same instructions. */
    for (uint32_t pass = 0; pass < BUSY_POLL_PASSES; ++pass) {
#else
    for (;;) {
#endif
        pinb_sum += PINB;
        if ((++iteration & 63u) == 0) {
            PORTD = ++portd_count;
        }
    }
#ifdef BUSY_POLL_PASSES
    /* The end of the work: a label a simulator's PC reaches once (QEMU's
     * run is timed to it). Then power-down with interrupts off, where simavr
     * ends its run. SE set: with SE = 0 a SLEEP is a NOP (ATmega328P
     * datasheet, SMCR: SE must be one for SLEEP to enter the sleep mode). */
    __asm__ __volatile__(".global busy_poll_done\n"
                         "busy_poll_done:\n\t");
    set_sleep_mode(SLEEP_MODE_PWR_DOWN);
    sleep_enable();
    cli();
    for (;;) {
        sleep_cpu();
    }
#endif
}
