/*
 * tmr_flag_enable - an interrupt enabled after its flag was set.
 *
 * Datasheet (ATmega328P §7.7 "Reset and Interrupt Handling"; ATmega2560 §7.8;
 * ATmega32 "Reset and Interrupt Handling"): "If an interrupt condition occurs
 * while the corresponding interrupt enable bit is cleared, the Interrupt Flag
 * will be set and remembered until the interrupt is enabled, or the flag is
 * cleared by software."
 *
 * Timer1 in CTC at clk/1 with OCR1A = 60000, interrupts on (sei) but OCIE1A
 * off. Once OCF1A is set (after 60001 cycles) the firmware toggles marker 0
 * (PC0, PF0 on the 2560) and on the next instruction sets OCIE1A; the vector
 * must run then, not 60001 cycles later at the next match. The ISR toggles
 * marker 1 first thing and turns OCIE1A off again (one run); `isr_count`.
 */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t isr_count;

#if TMR_MODERN
#define MASK1 TIMSK1
#define FLAGS1 TIFR1
#else
#define MASK1 TIMSK
#define FLAGS1 TIFR
#endif

ISR(TIMER1_COMPA_vect)
{
    MARK_TOGGLE(1);
    MASK1 = 0;
    ++isr_count;
}

int main(void)
{
    tmr_oc_outputs();
    OCR1A = 60000;
    TCCR1B = _BV(WGM12) | _BV(CS10);
    sei();
    while (!(FLAGS1 & _BV(OCF1A))) {
    }
    MARK_TOGGLE(0);
    MASK1 = _BV(OCIE1A);
    for (;;) {
    }
}
