/*
 * printer3d_drive - seed 001's per-motor drive board (§3.2, digest §1, §4):
 * an ATmega32 at 16 MHz that takes STEP/DIR/ENABLE from the interpolator and
 * switches the four half-windings of a unipolar stepper low-side, limiting
 * the current with a bang-bang chopper on the two sense resistors.
 *
 * Pins (the thesis' code comments): STEP PD2 = INT0 (rising edge), DIR PD0
 * (1 = CW: the sequence forward), ENABLE PD1 (1 = enabled), pull-ups on all
 * of Port D's inputs (DDRD = 0, PORTD = 0xFF, so open inputs read enabled and
 * CW); coils a / c / b / d on PB0 / PB1 / PB2 / PB3, stepping two phases on:
 * 0x05 (a b) -> 0x06 (c b) -> 0x0A (c d) -> 0x09 (a d) and back the other way;
 * sense a/c on ADC0 (PA0), b/d on ADC1 (PA1).
 *
 * Chopper (Code 3.6): on each sample of a pair's sense voltage, ADCH > 100
 * (1.97 V on the 5 V AVCC reference, 8 bits left-adjusted) switches that
 * pair off until its next sample; otherwise the pair follows the step state.
 * Conversions are triggered by Timer1 compare match B every 204 us (CTC at
 * clk/64, OCR1A = OCR1B = 50: 16 MHz / 64 / 51 = 4901.96 Hz), alternating
 * ADC0 and ADC1. Safety loop: ENABLE low drops all coils.
 *
 * Fixed against the listing (digest §9): the trigger source is Timer1
 * compare B (ADTS = 101; the thesis' 3 << ADTS0 is Timer0 compare, and
 * Timer0 never runs: no conversion ever happened), OCIE1B really enabled
 * (the thesis ORed the bit number 3 into TIMSK) with an interrupt that
 * clears OCF1B so every match triggers, the ADC clock at 16 MHz / 128 =
 * 125 kHz (the thesis' ADPS = 0 is 8 MHz), ADCH read as uint8_t (int8_t
 * wrapped codes >= 128 negative), and the step interrupt no longer nests
 * (ISR_NOBLOCK let the ADC interrupt's read-modify-write of PORTB interleave
 * with its own), and the main loop sleeps between interrupts instead of
 * spinning (the safety check runs after each one, at least every 204 us).
 * THESIS_LITERAL builds the listing as printed, with its hot-end control on
 * this MCU (Code 3.14-3.15: ADC2 in the round robin, the PID in raw int8_t
 * counts, OC2/PD7, TEMP_OK on PD6); THESIS_TRIGGER_FIXED on top fixes only
 * the conversion trigger (digest §9.1-9.3), so the later defects show.
 *
 * Globals for tests: position (steps, CW positive), motor_state, samples,
 * chops.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
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
#define ADC_PRESCALER 50 /* the thesis' name for the Timer1 compare value */

static const uint8_t sequence[4] = {COIL_A | COIL_B, COIL_C | COIL_B, COIL_C | COIL_D, COIL_A | COIL_D};

volatile int32_t position;
volatile uint8_t motor_state;
volatile uint16_t samples;
volatile uint16_t chops;
static uint8_t index_;
static uint8_t channel;
uint8_t chopped; /* pairs switched off by their last sample (not static: tests read it) */

#ifdef THESIS_LITERAL
ISR(INT0_vect, ISR_NOBLOCK)
#else
ISR(INT0_vect)
#endif
{
    if (!(PIND & _BV(PD1))) return; /* disabled: steps are ignored */
    index_ = (uint8_t)((index_ + ((PIND & _BV(PD0)) ? 1 : 3)) & 3);
    position += (PIND & _BV(PD0)) ? 1 : -1;
    motor_state = sequence[index_];
    PORTB = (uint8_t)((PORTB & 0xF0) | (motor_state & (uint8_t)~chopped));
}

#ifdef THESIS_LITERAL
/* The listing's hot-end control on the same MCU (Code 3.14-3.15, digest §5):
 * ADC2 joins the round robin AC -> BD -> TEMP, the PID runs on each
 * temperature sample in raw 8-bit counts read into an int8_t, Timer2 fast PWM
 * on OC2 = PD7, TEMP_OK on PD6. */
#define SENSE_TEMPERATURE 2
#define KP 200
#define KI 1
#define KD 500
#define REFERENCE_TEMP 190
#define TEMP_ACCEPTABLE_ERR 5
int16_t errorSum; /* not static: the bench's tests read them by their symbols */
int16_t previousError;
volatile uint16_t temperature_samples;

#ifdef THESIS_ADCH_UNSIGNED
/* §9.4 fixed as well: the counts 0..255 as they are, so §9.5 (raw counts
 * of an NTC in the lower leg: the error grows as the hot end heats) and
 * §9.6 (an unbounded int16_t errorSum) show on their own. */
static void temperature_sample(int16_t currentMeasurement)
#else
static void temperature_sample(int8_t currentMeasurement)
#endif
{
    const int16_t error = (int16_t)(REFERENCE_TEMP - currentMeasurement);
    int32_t temp = (int32_t)error * KP;
    errorSum += error;
    temp += (int32_t)errorSum * KI;
    temp += (int32_t)(error - previousError) * KD;
    previousError = error;
    OCR2 = temp > 255 ? 255 : temp < 0 ? 0 : (uint8_t)temp;
    if ((error < 0 ? -error : error) < TEMP_ACCEPTABLE_ERR) PORTD |= _BV(PD6);
    else PORTD &= (uint8_t)~_BV(PD6);
    ++temperature_samples;
}
#endif

ISR(ADC_vect)
{
#ifdef THESIS_LITERAL
#ifdef THESIS_ADCH_UNSIGNED
    const int16_t sample = ADCH;
#else
    const int8_t sample = (int8_t)ADCH;
#endif
    if (channel == SENSE_TEMPERATURE) {
        temperature_sample(sample);
        channel = 0;
        ADMUX = (uint8_t)(_BV(REFS0) | _BV(ADLAR) | channel);
        return;
    }
#else
    const uint8_t sample = ADCH;
#endif
    const uint8_t mask = channel == 0 ? MASK_AC : MASK_BD;
    ++samples;
    if (sample > CURRENT_LIMIT) {
        if (!(chopped & mask)) ++chops;
        chopped |= mask;
        PORTB &= (uint8_t)~mask;
    } else {
        chopped &= (uint8_t)~mask;
#ifndef THESIS_LITERAL
        if (PIND & _BV(PD1)) /* disabled coils stay off (the listing relies on its busy loop) */
#endif
            PORTB = (uint8_t)((PORTB & (uint8_t)~mask) | (motor_state & mask));
    }
#ifdef THESIS_LITERAL
    ++channel; /* AC -> BD -> TEMP */
#else
    channel ^= 1;
#endif
    ADMUX = (uint8_t)(_BV(REFS0) | _BV(ADLAR) | channel);
}

#if !defined(THESIS_LITERAL) || defined(THESIS_TRIGGER_FIXED)
EMPTY_INTERRUPT(TIMER1_COMPB_vect); /* taking it clears OCF1B, so the next match triggers again */
#endif

int main(void)
{
    DDRD = 0;
    PORTD = 0xFF; /* pull-ups: open inputs read enabled, CW */
    DDRB = 0xFF;
    index_ = 0;
    motor_state = sequence[0];
    PORTB = motor_state;
    MCUCR = _BV(ISC01) | _BV(ISC00); /* INT0 on the rising edge */
    GICR = _BV(INT0);
    ADMUX = _BV(REFS0) | _BV(ADLAR); /* AVCC, left adjusted, ADC0 */
    OCR1A = ADC_PRESCALER;
    OCR1B = ADC_PRESCALER;
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11) | _BV(CS10); /* CTC, clk/64 */
#ifdef THESIS_LITERAL
    DDRD |= (1 << 7); /* heater */
    PORTD &= (uint8_t)~(1 << 7);
    DDRD |= (1 << 6); /* TEMP_OK */
    TCCR2 = _BV(WGM21) | _BV(WGM20) | _BV(COM21) | _BV(CS22) | _BV(CS20); /* fast PWM, clk/128: 488 Hz */
#ifdef THESIS_TRIGGER_FIXED
    /* Only digest §9.1-9.3 fixed (the trigger, OCIE1B, the prescaler), so the
     * conversions run and §9.4-9.5 show: the int8_t ADCH and the raw counts. */
    SFIOR = (uint8_t)((SFIOR & 0x1F) | _BV(ADTS2) | _BV(ADTS0));
    TIMSK |= _BV(OCIE1B);
    ADCSRA = _BV(ADATE) | _BV(ADEN) | _BV(ADIE) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0);
#else
    SFIOR = (3 << ADTS0);
    TIMSK |= OCIE1B;
    ADCSRA = _BV(ADATE) | _BV(ADEN) | _BV(ADIE) | (128);
#endif
#else
    SFIOR = (uint8_t)((SFIOR & 0x1F) | _BV(ADTS2) | _BV(ADTS0)); /* Timer1 compare match B */
    TIMSK |= _BV(OCIE1B);
    ADCSRA = _BV(ADATE) | _BV(ADEN) | _BV(ADIE) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0);
#endif
    sei();
#ifdef THESIS_LITERAL
    for (;;) {
        if (!(PIND & _BV(PD1))) PORTB &= 0xF0; /* safety: disabled, coils off */
    }
#else
    /* The safety loop runs after every interrupt - at the latest the Timer1
     * match every 204 us - and sleeps in between (idle mode: the timers, the
     * ADC and INT0 run on). */
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) {
        cli();
        if (!(PIND & _BV(PD1))) PORTB &= 0xF0; /* safety: disabled, coils off */
        sleep_enable();
        sei();
        sleep_cpu(); /* SEI lets exactly this SLEEP run before a pending interrupt */
        sleep_disable();
    }
#endif
}
