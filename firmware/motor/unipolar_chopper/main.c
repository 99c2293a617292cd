/*
 * unipolar_chopper - seed 001's unipolar drive board (§3.2, digest §4): an
 * ATmega32 at 16 MHz switches the four half-windings of a six-wire stepper
 * low-side (coil a, c, b, d on PB0..PB3), centre taps at the supply, and
 * limits the current with the thesis's bang-bang chopper (Code 3.6):
 *
 *     if (ADCH > CURRENT_LIMIT) PORTB &= ~mask; else PORTB |= (motorState & mask);
 *
 * on each sample of the pair's sense resistor (A/C on ADC0, B/D on ADC1).
 * Corrected where the thesis is not (digest §8): the ADC really runs (each
 * conversion is started explicitly, ADC clock 16 MHz / 128 = 125 kHz, 13
 * clocks = 104 us per conversion, channels alternating, so each pair is
 * sampled every 208 us), ADCH is read as uint8_t (the thesis's int8_t wraps
 * codes >= 128 to negative), and the steps come from Timer1 instead of the
 * interpolator's STEP line: full steps, two phases on, sequence AB -> BC ->
 * CD -> DA (§3.2.5), STEP_RATE steps/s for STEPS steps, then holding.
 *
 * AVCC = 5 V reference, ADLAR, 8-bit ADCH: CURRENT_LIMIT 100 chops above
 * 101 * 5 V / 256 = 1.97 V across R_sense.
 * Globals: steps, chops (samples that switched a pair off), max_adch[2].
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define COIL_A _BV(PB0)
#define COIL_C _BV(PB1)
#define COIL_B _BV(PB2)
#define COIL_D _BV(PB3)
#define MASK_AC (COIL_A | COIL_C)
#define MASK_BD (COIL_B | COIL_D)
#define CURRENT_LIMIT 100

#ifndef STEP_RATE
#define STEP_RATE 200 /* full steps per second: 60 rpm */
#endif
#ifndef STEPS
#define STEPS 400
#endif

static const uint8_t sequence[4] = {COIL_A | COIL_B, COIL_B | COIL_C, COIL_C | COIL_D, COIL_D | COIL_A};

volatile uint16_t steps;
volatile uint16_t chops;
volatile uint8_t max_adch[2];
static volatile uint8_t motor_state;
static uint8_t index_;
static uint8_t channel;

ISR(TIMER1_COMPA_vect)
{
    if (steps >= STEPS) return; /* hold the last step */
    index_ = (uint8_t)((index_ + 1) & 3);
    motor_state = sequence[index_];
    PORTB = (uint8_t)((PORTB & 0xF0) | motor_state);
    steps++;
}

ISR(ADC_vect)
{
    const uint8_t sample = ADCH;
    const uint8_t mask = channel == 0 ? MASK_AC : MASK_BD;
    if (sample > max_adch[channel]) max_adch[channel] = sample;
    if (sample > CURRENT_LIMIT) {
        if (PORTB & mask) chops++;
        PORTB &= (uint8_t)~mask;
    } else {
        PORTB |= (uint8_t)(motor_state & mask);
    }
    channel ^= 1;
    ADMUX = (uint8_t)(_BV(REFS0) | _BV(ADLAR) | channel);
    ADCSRA |= _BV(ADSC);
}

int main(void)
{
    DDRB = 0x0F;
    motor_state = sequence[0];
    PORTB = motor_state;
    ADMUX = _BV(REFS0) | _BV(ADLAR); /* AVCC reference, left adjusted, ADC0 */
    ADCSRA = _BV(ADEN) | _BV(ADIE) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0);
    OCR1A = (uint16_t)(F_CPU / 64 / STEP_RATE - 1);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11) | _BV(CS10); /* CTC, clk/64 */
    TIMSK = _BV(OCIE1A);
    sei();
    ADCSRA |= _BV(ADSC);
    for (;;) {
    }
}
