/*
 * irq_latency - interrupt response time, "one more instruction" after SEI and
 * RETI, and (built with -DNESTED) an interrupt nested in an ISR that sets I.
 *
 * ATmega328P §7.7 / §7.7.1, ATmega2560 §7.8 / §7.8.1, ATmega32 "Reset and
 * Interrupt Handling":
 *   - the response to an enabled interrupt takes 4 cycles (5 on the 2560,
 *     3-byte PC), then the vector's JMP takes 3;
 *   - the instruction following SEI is executed before any pending interrupt;
 *   - after RETI (4 cycles; 5 on the 2560) one more instruction of the
 *     interrupted code runs before a pending interrupt is served.
 *
 * With interrupts off, INT0 and INT1 are set to rising edge and their pins
 * (outputs: "a way of generating a software interrupt", §13) are driven high,
 * so both flags are set and both interrupts pend. Then, in assembly:
 *
 *   ldi r24,0 ; sbi PORTB,0 ; sei ; inc r24 (x6) ; sts main_count,r24
 *
 * r24 counts the main-line instructions executed; each ISR stores it on entry.
 * INT0 has the higher priority. Markers: PB0 before SEI, PB1 in INT0, PB2 in
 * INT1 (set by each ISR's first instruction).
 *
 * Default build: INT0 = sbi PB1 ; sts int0_seen,r24 ; cbi PB1 ; reti
 *                INT1 = sbi PB2 ; sts int1_seen,r24 ; cbi PB2 ; reti
 * NESTED build:  INT0 = sbi PB1 ; sei ; inc r24 (x3) ; sts int0_seen,r24 ;
 *                       cbi PB1 ; reti      (ISR_NOBLOCK style)
 *                INT1 as above.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t main_count;
volatile uint8_t int0_seen;
volatile uint8_t int1_seen;

ISR(INT0_vect, ISR_NAKED)
{
#ifdef NESTED
    asm volatile("sbi %[portb], 1\n\t"
                 "sei\n\t"
                 "inc r24\n\t"
                 "inc r24\n\t"
                 "inc r24\n\t"
                 "sts int0_seen, r24\n\t"
                 "cbi %[portb], 1\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB));
#else
    asm volatile("sbi %[portb], 1\n\t"
                 "sts int0_seen, r24\n\t"
                 "cbi %[portb], 1\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB));
#endif
}

ISR(INT1_vect, ISR_NAKED)
{
    asm volatile("sbi %[portb], 2\n\t"
                 "sts int1_seen, r24\n\t"
                 "cbi %[portb], 2\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB));
}

int main(void)
{
    cli();
    DDRB = 0x0F;
    PORTB = 0;
    EXT_SENSE = (1 << ISC01) | (1 << ISC00) | (1 << ISC11) | (1 << ISC10); /* rising edges */
    EXT_FLAGS = (1 << INTF0) | (1 << INTF1);
    EXT_MASK = (1 << INT0) | (1 << INT1);
    DDRD |= (1 << INT0_PIN) | (1 << INT1_PIN);
    PORTD |= (1 << INT0_PIN) | (1 << INT1_PIN); /* both flags set, both pending, I = 0 */

    asm volatile("ldi r24, 0\n\t"
                 "sbi %[portb], 0\n\t"
                 "sei\n\t"
                 "inc r24\n\t"
                 "inc r24\n\t"
                 "inc r24\n\t"
                 "inc r24\n\t"
                 "inc r24\n\t"
                 "inc r24\n\t"
                 "sts main_count, r24\n\t" ::[portb] "I"(IO_PORTB)
                 : "r24", "memory");
    for (;;) {
    }
}
