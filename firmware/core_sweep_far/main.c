/*
 * core_sweep_far - the ATmega2560's far flash and far jumps, for the
 * predecoded core's instruction-by-instruction comparison with simavr's
 * avr_run_one (tests/core/test_predecoded_core.cpp): every form of ELPM
 * (R0 <- (RAMPZ:Z); Rd <- (RAMPZ:Z); Rd <- (RAMPZ:Z), Z+) with RAMPZ 0 to 3
 * and Z at the ends of each 64 KB bank (Z+ from 0xFFFF carries into RAMPZ),
 * EICALL and EIJMP through EIND. Compiled C reaches ELPM Z+ only in the
 * start-up's .data copy, and the other forms not at all. What is read
 * folds into `far_sum`; then the MCU stops (power-down with interrupts
 * off). The flash read is whatever is there (code, or erased 0xFF): both
 * cores read the same bytes.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t far_sum;
volatile uint8_t far_calls;

__attribute__((noinline, used)) void far_callee(void) { far_calls++; }

int main(void)
{
    uint16_t sum = 0;
    static const uint16_t zs[] = {0x0000, 0x0001, 0x7fff, 0xfffe, 0xffff};
    for (uint8_t bank = 0; bank < 4; ++bank) {
        for (uint8_t i = 0; i < sizeof zs / sizeof zs[0]; ++i) {
            const uint16_t z = zs[i];
            uint8_t a, b, c, rampz_after;
            /* ELPM r0; ELPM r24, Z; ELPM r25, Z+ (RAMPZ:Z moves on by one). */
            __asm__ __volatile__("out %[rampz], %[bank]\n\t"
                                 "movw r30, %[z]\n\t"
                                 "elpm\n\t"
                                 "mov %[a], r0\n\t"
                                 "elpm %[b], Z\n\t"
                                 "elpm %[c], Z+\n\t"
                                 "in %[after], %[rampz]\n\t"
                                 : [a] "=&r"(a), [b] "=&r"(b), [c] "=&r"(c), [after] "=&r"(rampz_after)
                                 : [rampz] "I"(_SFR_IO_ADDR(RAMPZ)), [bank] "r"(bank), [z] "r"(z)
                                 : "r0", "r30", "r31");
            sum = (uint16_t)(sum * 31u + a + b + c + rampz_after);
        }
    }
    RAMPZ = 0;
    /* EICALL and EIJMP with EIND 0 (the callee and the label are in the first 128 KB). */
    __asm__ __volatile__("out %[eind], __zero_reg__\n\t"
                         "ldi r30, lo8(gs(far_callee))\n\t"
                         "ldi r31, hi8(gs(far_callee))\n\t"
                         "eicall\n\t"
                         "ldi r30, lo8(gs(1f))\n\t"
                         "ldi r31, hi8(gs(1f))\n\t"
                         "eijmp\n\t"
                         "rjmp .\n\t"  /* never: EIJMP goes past it */
                         "1:\n\t"
                         :
                         : [eind] "I"(_SFR_IO_ADDR(EIND))
                         : "r30", "r31", "r18", "r19", "r20", "r21", "r22", "r23", "r24", "r25", "r26", "r27", "memory");
    far_sum = sum;
    cli();
    set_sleep_mode(SLEEP_MODE_PWR_DOWN);
    sleep_enable();
    for (;;) sleep_cpu();
}
