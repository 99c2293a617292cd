/*
 * limit_probe - homes the CNC shield's X axis onto its limit switch and back
 * off, the way a homing cycle does, and counts what the limit input did.
 *
 *   X STEP PD2, DIR PD5 (low = towards the switch), enable PB0 (low),
 *   X limit PB1: input with the internal pull-up (PORTB1 = 1), switch to GND,
 *   so it reads 0 while the switch is closed. A pin-change interrupt
 *   (PCINT1, PCIE0) counts every edge on it, bounce included.
 *
 * Each step: STEP high 32 cycles, low >= 320 cycles (A4988: >= 16 each).
 * Results in globals: steps_to_trip (steps towards the switch until the input
 * read 0), steps_to_release (steps back until it read 1 again), pcint_edges,
 * done = 1 at the end.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t steps_to_trip;
volatile uint16_t steps_to_release;
volatile uint8_t pcint_edges;
volatile uint8_t done;

ISR(PCINT0_vect)
{
    ++pcint_edges;
}

static void step(void)
{
    PORTD |= _BV(PD2);
    __builtin_avr_delay_cycles(30);
    PORTD &= (uint8_t)~_BV(PD2);
    __builtin_avr_delay_cycles(320);
}

int main(void)
{
    DDRD = _BV(PD2) | _BV(PD5);
    DDRB = _BV(PB0);
    PORTB = _BV(PB1); /* EN low (enabled), pull-up on the limit input */
    PCMSK0 = _BV(PCINT1);
    PCICR = _BV(PCIE0);
    sei();
    __builtin_avr_delay_cycles(1600);

    PORTD &= (uint8_t)~_BV(PD5); /* towards the switch */
    __builtin_avr_delay_cycles(16);
    while ((PINB & _BV(PB1)) && steps_to_trip < 60000) {
        step();
        ++steps_to_trip;
    }
    /* 5 ms for any bounce to die out before backing off. */
    for (uint8_t i = 0; i < 50; ++i) __builtin_avr_delay_cycles(1600);

    PORTD |= _BV(PD5); /* away from the switch */
    __builtin_avr_delay_cycles(16);
    while (!(PINB & _BV(PB1)) && steps_to_release < 60000) {
        step();
        ++steps_to_release;
    }
    for (uint8_t i = 0; i < 50; ++i) __builtin_avr_delay_cycles(1600);
    done = 1;
    for (;;) {
    }
}
