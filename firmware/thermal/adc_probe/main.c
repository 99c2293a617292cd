/*
 * adc_probe - converts analog inputs over and over and keeps the results in
 * globals, for the bench's ADC and thermistor tests. Single conversions,
 * polled on ADSC, prescaler 128.
 *
 *   atmega2560: AVCC reference. adc_ch[0..3] = ADC13 (PK5, RAMPS T0),
 *               ADC14 (PK6), ADC15 (PK7), ADC0 (PF0), right-adjusted 10 bits;
 *               adc_high8 = ADCH of ADC13 with ADLAR set (8-bit read).
 *   atmega328p: AVCC reference. adc_ch[0..1] = ADC0 (PC0), ADC5 (PC5);
 *               adc_ch[2] = the 1.1 V bandgap (MUX = 1110) against AVCC.
 *   atmega32:   seed 001's arrangement: AVCC reference, ADLAR, ADC2 (PA2),
 *               only ADCH read: adc_high8. Heater PWM as in seed 001:
 *               Timer2 fast PWM, non-inverting OC2 = PD7, clk/128
 *               (TCCR2 = WGM21|WGM20|COM21|CS22|CS20, 488.28 Hz), OCR2 = HEATER_DUTY.
 *
 * rounds counts completed passes.
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#ifndef HEATER_DUTY
#define HEATER_DUTY 0
#endif

volatile uint16_t adc_ch[4];
volatile uint8_t adc_high8;
volatile uint16_t rounds;

static __attribute__((unused)) uint16_t convert(uint8_t admux, uint8_t mux5)
{
#ifdef MUX5
    if (mux5) ADCSRB |= _BV(MUX5); else ADCSRB &= (uint8_t)~_BV(MUX5);
#else
    (void)mux5;
#endif
    ADMUX = admux;
    ADCSRA |= _BV(ADSC);
    while (ADCSRA & _BV(ADSC)) {
    }
    return ADC;
}

int main(void)
{
    ADCSRA = _BV(ADEN) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0);
#if defined(__AVR_ATmega32__)
    DDRD |= _BV(PD7);
    OCR2 = HEATER_DUTY;
    TCCR2 = _BV(WGM21) | _BV(WGM20) | _BV(COM21) | _BV(CS22) | _BV(CS20);
#endif
    for (;;) {
#if defined(__AVR_ATmega2560__)
        adc_ch[0] = convert(_BV(REFS0) | 5, 1);
        adc_ch[1] = convert(_BV(REFS0) | 6, 1);
        adc_ch[2] = convert(_BV(REFS0) | 7, 1);
        adc_ch[3] = convert(_BV(REFS0) | 0, 0);
        (void)convert(_BV(REFS0) | _BV(ADLAR) | 5, 1);
        adc_high8 = ADCH;
#elif defined(__AVR_ATmega328P__)
        adc_ch[0] = convert(_BV(REFS0) | 0, 0);
        adc_ch[1] = convert(_BV(REFS0) | 5, 0);
        adc_ch[2] = convert(_BV(REFS0) | 0x0E, 0);
#elif defined(__AVR_ATmega32__)
        ADMUX = _BV(REFS0) | _BV(ADLAR) | 2;
        ADCSRA |= _BV(ADSC);
        while (ADCSRA & _BV(ADSC)) {
        }
        adc_high8 = ADCH;
#endif
        ++rounds;
    }
}
