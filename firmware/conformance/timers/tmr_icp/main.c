/*
 * tmr_icp - Timer1 input capture, both edges, with and without the noise
 * canceler.
 *
 * Datasheet (ATmega328P §16.6 "Input Capture Unit"): on the edge ICES1
 * selects on ICP1 (1 rising, 0 falling) the value of TCNT1 is written to ICR1
 * and ICF1 is set; §16.6.2 "Noise Canceler": "The noise canceler uses the
 * output of the edge detector ... the input is monitored over four samples,
 * and all four must be equal for changing the output", which "delays the
 * update of ICR1 by four system clock cycles" (ICNC1 = 1, TCCR1B bit 7).
 *
 * Timer1 Normal mode, clk/1, ICIE1 on. The capture vector stores ICR1 in
 * `cap[]` (up to 8), flips ICES1 so the next capture is on the other edge,
 * and after the fourth capture sets ICNC1. The bench drives ICP1 (PB0 on the
 * 328P, PD4 on the 2560, PD6 on the ATmega32) from outside.
 */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t cap[8];
volatile uint8_t count;

#if TMR_MODERN
#define MASK1 TIMSK1
#define CAPTURE_ENABLE ICIE1
#else
#define MASK1 TIMSK
#define CAPTURE_ENABLE TICIE1
#endif

ISR(TIMER1_CAPT_vect)
{
    const uint16_t v = ICR1;
    if (count < 8) cap[count++] = v;
    TCCR1B ^= _BV(ICES1);
    if (count == 4) TCCR1B |= _BV(ICNC1);
}

int main(void)
{
    TCCR1A = 0;
    MASK1 = _BV(CAPTURE_ENABLE);
    TCCR1B = _BV(ICES1) | _BV(CS10);
    sei();
    for (;;) {
    }
}
