/*
 * pcint_relay - copies input PB1 to output PC0 from an interrupt and sleeps
 * (IDLE) in between: a link in a chain of MCUs for the lockstep's tests.
 *
 * Built twice (firmware/CMakeLists.txt):
 *   pcint_relay_wake  (RELAY_ON_PIN_CHANGE=1): PCINT1 (PB1) wakes it on every
 *     change of PB1 (ATmega328P §13.2.4 PCICR.PCIE0, §13.2.6 PCMSK0.PCINT1);
 *     PC0 follows PB1 a few cycles after the edge.
 *   pcint_relay_poll  (RELAY_ON_PIN_CHANGE=0): nothing on PB1 can wake it;
 *     Timer0's overflow does, every 256 * 64 = 16384 cycles (1.024 ms at
 *     16 MHz: TCCR0B CS01|CS00 = clk/64, §15.9.2), and PC0 takes PB1's level
 *     then - up to 1.024 ms late.
 *   pcint_relay_gated (RELAY_ON_PIN_CHANGE=2): PCINT1 copies as in _wake,
 *     but Timer0's overflow (every 1.024 ms, as in _poll) opens and closes
 *     the gate, PCICR.PCIE0, in turn: whether a change of PB1 can wake it
 *     changes while it runs (the lockstep's remembered wake-ups).
 *     Changes while the gate is closed are copied when it opens (PCIF0
 *     stays set, §13.2.5).
 * `copies` counts the copies made.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#ifndef RELAY_ON_PIN_CHANGE
#error "pcint_relay: define RELAY_ON_PIN_CHANGE to 0 or 1"
#endif

volatile uint16_t copies;

static void copy(void)
{
    if (PINB & _BV(PINB1)) {
        PORTC |= _BV(PORTC0);
    } else {
        PORTC &= (uint8_t)~_BV(PORTC0);
    }
    ++copies;
}

#if RELAY_ON_PIN_CHANGE
ISR(PCINT0_vect)
{
    copy();
}
#if RELAY_ON_PIN_CHANGE == 2
ISR(TIMER0_OVF_vect)
{
    PCICR ^= _BV(PCIE0);
}
#endif
#else
ISR(TIMER0_OVF_vect)
{
    copy();
}
#endif

int main(void)
{
    DDRC = _BV(DDC0); /* PB1 stays an input without pull-up: the net drives it */
#if RELAY_ON_PIN_CHANGE
    PCMSK0 = _BV(PCINT1);
    PCICR = _BV(PCIE0);
#if RELAY_ON_PIN_CHANGE == 2
    TIMSK0 = _BV(TOIE0);
    TCCR0B = _BV(CS01) | _BV(CS00);
#endif
#else
    TIMSK0 = _BV(TOIE0);
    TCCR0B = _BV(CS01) | _BV(CS00);
#endif
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();
    for (;;) {
        sleep_enable();
        sleep_cpu();
        sleep_disable();
    }
}
