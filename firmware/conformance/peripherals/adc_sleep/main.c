/*
 * adc_sleep - ADC Noise Reduction mode starts a conversion (ATmega328P §10.4,
 * §24.6; 2560 §11.4, §26.6; m32 "ADC Noise Reduction Mode", "ADC Noise
 * Canceler"): "If the ADC is enabled, a conversion starts automatically when
 * this mode is entered"; the ADC Conversion Complete interrupt wakes the part.
 *
 * Channel 2, AVCC reference, prescaler 16, ADIE on. One warm-up conversion by
 * ADSC (the first one after ADEN takes 25 ADC clocks), then
 * `sbi PORTB,0 ; sleep` in ADC Noise Reduction mode with no conversion
 * running. The naked ADC ISR sets PB1 and stores ADCL/ADCH in `result`.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t result;
volatile uint8_t woke;

ISR(ADC_vect, ISR_NAKED)
{
    asm volatile("sbi %[portb], 1\n\t"
                 "push r24\n\t"
                 "lds r24, %[adcl]\n\t"
                 "sts result, r24\n\t"
                 "lds r24, %[adch]\n\t"
                 "sts result+1, r24\n\t"
                 "pop r24\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB),
                 [adcl] "n"(_SFR_MEM_ADDR(ADCL)), [adch] "n"(_SFR_MEM_ADDR(ADCH)));
}

int main(void)
{
    DDRB = 0x03;
    ADMUX = (1 << REFS0) | 2;
    ADCSRA = (1 << ADEN) | (1 << ADSC) | (1 << ADPS2);
    while (ADCSRA & (1 << ADSC)) {
    }
    ADCSRA = (1 << ADEN) | (1 << ADIF) | (1 << ADIE) | (1 << ADPS2); /* clear ADIF, enable ADIE */
    set_sleep_mode(SLEEP_MODE_ADC);
    sleep_enable();
    sei();
    asm volatile("sbi %[portb], 0\n\t"
                 "sleep\n\t" ::[portb] "I"(IO_PORTB));
    woke = 1;
    for (;;) {
    }
}
