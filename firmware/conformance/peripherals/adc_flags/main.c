/*
 * adc_flags - ADIF, ADIE and the ADCL/ADCH read lock (ATmega328P §24.2,
 * §24.9.2; 2560 §26.2, §26.8.2; m32 ADCSRA).
 *
 *  - "ADIF is cleared by writing a logical one to the flag";
 *  - a flag set while its interrupt is disabled is remembered until the
 *    interrupt is enabled (§7.7): setting ADIE with ADIF set interrupts;
 *  - "if ADCL has been read, and a conversion completes before ADCH is read,
 *    neither register is updated and the result from the conversion is lost".
 *
 * Channel 1, AVCC reference, prescaler 16, no ADIE, interrupts on:
 *  1. Start, wait for ADIF, store ADCW in `first`; write a one to ADIF, store
 *     ADCSRA in `adcsra_after_clear`.
 *  2. Marker PB0 (the bench changes the channel 1 voltage). Start, wait for
 *     ADIF, read ADCL only (into `low_locked`); start again, wait for that
 *     ADIF, read ADCH (`high_locked`) then ADCL/ADCH again (`after_lock`).
 *  3. ADIF still set: enable ADIE (writing ADIF as 0) -> the ISR runs
 *     (`isr_count` = 1).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t first;
volatile uint8_t adcsra_after_clear = 0xFF;
volatile uint8_t low_locked, high_locked;
volatile uint16_t after_lock;
volatile uint8_t isr_count;

ISR(ADC_vect)
{
    ++isr_count;
    ADCSRA &= (uint8_t) ~(1 << ADIE);
}

static void convert(void)
{
    ADCSRA = (uint8_t)((ADCSRA & ~(1 << ADIF)) | (1 << ADSC)); /* ADIF written 0: kept */
    while (!(ADCSRA & (1 << ADIF))) {
    }
}

int main(void)
{
    DDRB = 0x01;
    sei();
    ADMUX = (1 << REFS0) | 1;
    ADCSRA = (1 << ADEN) | (1 << ADPS2);

    /* 1 */
    convert();
    first = ADCW;
    ADCSRA |= (1 << ADIF);
    adcsra_after_clear = ADCSRA;

    /* 2 */
    PORTB |= (1 << PB0);
    for (volatile uint16_t i = 0; i < 200; ++i) {
    }
    convert();
    ADCSRA |= (1 << ADIF);
    low_locked = ADCL;
    convert();
    high_locked = ADCH;
    after_lock = ADCW;

    /* 3: write ADIF as 0 (a read-modify-write `ADCSRA |= ADIE` would write the
     * set ADIF back as a one and clear it: the datasheet's warning about
     * read-modify-write on ADCSRA). */
    ADCSRA = (uint8_t)((ADCSRA & ~(1 << ADIF)) | (1 << ADIE));
    for (volatile uint8_t i = 0; i < 10; ++i) {
    }
    for (;;) {
    }
}
