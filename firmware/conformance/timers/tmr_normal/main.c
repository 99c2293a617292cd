/*
 * tmr_normal - Normal mode: the counter runs BOTTOM..MAX and wraps.
 *
 * Datasheet (ATmega328P §15.7.1 / §16.9.1 / §18.7.1): "the counting direction
 * is always up (incrementing), and no counter clear is performed. The counter
 * simply overruns when it passes its maximum 8-bit value (TOP = 0xFF) and then
 * restarts from the bottom (0x00)"; the OCnA toggle (COMnA = 01) on its match
 * therefore comes every (MAX + 1) * N cycles, and TOVn once per wrap.
 *
 *   timer  N   OCRnA  toggle interval
 *   0      1   10     256
 *   1      1   1000   65536
 *   2      8   10     2048
 *   3      1   0      65536  (2560)
 *   4      8   0      524288 (2560)
 *   5      1   65535  65536  (2560)
 * Timer0's overflow interrupt (TOIE0) counts wraps in `overflows` (16 bits).
 */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t overflows;

ISR(TIMER0_OVF_vect) { ++overflows; }

int main(void)
{
    tmr_oc_outputs();
    OCR1A = 1000;
    TCCR1A = _BV(COM1A0);
#if TMR_MODERN
    OCR0A = 10;
    TCCR0A = _BV(COM0A0);
    OCR2A = 10;
    TCCR2A = _BV(COM2A0);
    TIMSK0 = _BV(TOIE0);
#if TMR_SIX
    OCR3A = 0;
    TCCR3A = _BV(COM3A0);
    OCR4A = 0;
    TCCR4A = _BV(COM4A0);
    OCR5A = 65535;
    TCCR5A = _BV(COM5A0);
    TCCR3B = _BV(CS30);
    TCCR4B = _BV(CS41);
    TCCR5B = _BV(CS50);
#endif
    TCCR0B = _BV(CS00);
    TCCR1B = _BV(CS10);
    TCCR2B = _BV(CS21);
#else
    OCR0 = 10;
    OCR2 = 10;
    TIMSK = _BV(TOIE0);
    TCCR0 = _BV(COM00) | _BV(CS00);
    TCCR1B = _BV(CS10);
    TCCR2 = _BV(COM20) | _BV(CS21);
#endif
    sei();
    for (;;) {
    }
}
