/*
 * adc_modes - ADC conversion timing, channel latching in Free Running mode,
 * and auto-trigger sources.
 *
 * ATmega328P §24.3-24.5 and §24.9 (2560 §26.4-26.6, §26.8; m32 "Analog to
 * Digital Converter", SFIOR): the ADC clock is the CPU clock divided by the
 * ADPS prescaler (here ADPS2:0 = 100: /16); a conversion starts at the next
 * rising ADC clock edge and takes 13 ADC clocks, the first one after ADEN 25,
 * an auto-triggered one 13.5 (Table 24-1); the channel is locked when a
 * conversion starts; in Free Running mode "the next result will reflect the
 * previous channel selection" after a channel change; a trigger is the
 * rising edge of the selected interrupt flag, "the Interrupt Flag must be
 * cleared in order to trigger a new conversion".
 *
 * Reference AVCC (REFS1:0 = 01). The main line sleeps in Idle between
 * results (the timers and the ADC run; the bench sees every event at its exact
 * cycle). The ADC ISR stores ADCW in results[count++].
 *
 * Phase  ADMUX channel        results[]  how
 *  A     1                    0          first conversion: ADEN|ADSC together
 *  B     2                    1          single conversion (ADSC)
 *  C     3, then 4            2..5       Free Running; the ISR switches to
 *                                        channel 4 after results[2]
 *  D     5                    6..8       Timer1 compare match B (ADTS = 101);
 *                                        Timer1 CTC, OCR1A = 999, OCR1B = 400,
 *                                        clk/1; the ISR clears OCF1B
 *  E     5                    -          same, OCF1B never cleared: one
 *                                        conversion only (count_no_clear = 1)
 *  F     6                    9..10      Timer0 overflow (ADTS = 100), clk/8,
 *                                        TOIE0 on (its ISR clears TOV0)
 *  H     0                    11..12     Timer0 compare match (A) (ADTS = 011,
 *                                        seed 001's choice), Timer0 normal mode,
 *                                        clk/8, OCR0(A) = 100, its ISR clears the flag
 *  G     7                    13..14     INT0 (ADTS = 010), falling edge, INT0
 *                                        disabled; the ADC ISR clears INTF0;
 *                                        the bench makes the edges
 * Markers: PB0 set at the start of G (the bench then makes two falling
 * edges), PB1 at the end.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

#if defined(__AVR_ATmega32__)
#define TIMER1_FLAGS TIFR
#define TIMER0_FLAGS TIFR
#define TIMER0_MASK TIMSK
#define TIMER0_START() (TCCR0 = (1 << CS01))
#define TIMER0_STOP() (TCCR0 = 0)
#define TIMER0_CMP_FLAG OCF0
#define TIMER0_CMP_REG OCR0
#define TIMER0_CMP_IE OCIE0
#define TIMER0_CMP_VECT TIMER0_COMP_vect
static void set_trigger(uint8_t adts) { SFIOR = (uint8_t)((SFIOR & 0x1F) | (adts << 5)); }
#else
#define TIMER1_FLAGS TIFR1
#define TIMER0_FLAGS TIFR0
#define TIMER0_MASK TIMSK0
#define TIMER0_START() (TCCR0B = (1 << CS01))
#define TIMER0_STOP() (TCCR0B = 0)
#define TIMER0_CMP_FLAG OCF0A
#define TIMER0_CMP_REG OCR0A
#define TIMER0_CMP_IE OCIE0A
#define TIMER0_CMP_VECT TIMER0_COMPA_vect
static void set_trigger(uint8_t adts) { ADCSRB = (uint8_t)((ADCSRB & ~0x07) | adts); }
#endif

#define ADPS_16 ((1 << ADPS2))
#define REF_AVCC (1 << REFS0)

volatile uint16_t results[16];
volatile uint8_t count;
volatile uint8_t phase;
volatile uint8_t count_no_clear;

ISR(ADC_vect)
{
    const uint16_t v = ADCW;
    if (count < 16) results[count] = v;
    ++count;
    if (phase == 'C' && count == 3) ADMUX = REF_AVCC | 4;
    if (phase == 'D') TIMER1_FLAGS = (1 << OCF1B);
    if (phase == 'G') EXT_FLAGS = (1 << INTF0);
}

ISR(TIMER0_OVF_vect) {}
ISR(TIMER0_CMP_VECT) {}

static void wait_count(uint8_t n)
{
    while (count < n) {
        sleep_cpu();
    }
}

int main(void)
{
    DDRB = 0x03;
    PORTD |= (1 << INT0_PIN);
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();
    sei();

    phase = 'A';
    ADMUX = REF_AVCC | 1;
    ADCSRA = (1 << ADEN) | (1 << ADSC) | (1 << ADIE) | ADPS_16;
    wait_count(1);

    phase = 'B';
    ADMUX = REF_AVCC | 2;
    ADCSRA |= (1 << ADSC);
    wait_count(2);

    phase = 'C';
    ADMUX = REF_AVCC | 3;
    set_trigger(0);
    ADCSRA |= (1 << ADATE) | (1 << ADSC);
    wait_count(6);
    ADCSRA &= (uint8_t) ~(1 << ADATE);
    while (ADCSRA & (1 << ADSC)) {
    }
    count = 6;

    phase = 'D';
    ADMUX = REF_AVCC | 5;
    set_trigger(5);
    TIMER1_FLAGS = (1 << OCF1B);
    OCR1A = 999;
    OCR1B = 400;
    TCNT1 = 0;
    ADCSRA |= (1 << ADATE);
    TCCR1B = (1 << WGM12) | (1 << CS10);
    wait_count(9);

    phase = 'E'; /* the ISR stops clearing OCF1B */
    while (ADCSRA & (1 << ADSC)) {
    }
    const uint8_t before = count;
    TIMER1_FLAGS = (1 << OCF1B); /* armed for one more trigger */
    for (volatile uint16_t i = 0; i < 1500; ++i) { /* > 10 compare periods */
    }
    count_no_clear = (uint8_t)(count - before);
    TCCR1B = 0;
    ADCSRA &= (uint8_t) ~(1 << ADATE);
    count = 9;

    phase = 'F';
    ADMUX = REF_AVCC | 6;
    set_trigger(4);
    TIMER0_FLAGS = (1 << TOV0);
    TIMER0_MASK |= (1 << TOIE0);
    ADCSRA |= (1 << ADATE);
    TIMER0_START();
    wait_count(11);
    TIMER0_STOP();
    TIMER0_MASK &= (uint8_t) ~(1 << TOIE0);
    ADCSRA &= (uint8_t) ~(1 << ADATE);

    phase = 'H';
    ADMUX = REF_AVCC | 0;
    set_trigger(3);
    TIMER0_FLAGS = (1 << TIMER0_CMP_FLAG);
    TIMER0_CMP_REG = 100;
    TIMER0_MASK |= (1 << TIMER0_CMP_IE);
    ADCSRA |= (1 << ADATE);
    TIMER0_START();
    wait_count(13);
    TIMER0_STOP();
    TIMER0_MASK &= (uint8_t) ~(1 << TIMER0_CMP_IE);
    ADCSRA &= (uint8_t) ~(1 << ADATE);

    phase = 'G';
    ADMUX = REF_AVCC | 7;
    EXT_SENSE = (1 << ISC01); /* INT0 falling edge, interrupt disabled */
    EXT_FLAGS = (1 << INTF0);
    set_trigger(2);
    ADCSRA |= (1 << ADATE);
    PORTB |= (1 << PB0);
    wait_count(15);
    ADCSRA &= (uint8_t) ~(1 << ADATE);
    PORTB |= (1 << PB1);
    for (;;) {
    }
}
