/*
 * tmr_ctc_ocr0 - CTC mode with OCRnA = 0 at prescaler 1: a compare match on
 * every timer clock, i.e. every CPU cycle.
 *
 * Datasheet (ATmega328P §15.7.2 / §16.9.2 / §18.7.2): "The waveform generated
 * will have a maximum frequency of f_OC0 = f_clk_I/O/2 when OCR0A is set to
 * zero (0x00)": OCnA toggles on every cycle.
 *
 * Every timer is started in CTC, OCRnA = 0, clk/1, COMnA = 01 (toggle), one
 * after the other, and stopped one after the other about 200 cycles later.
 * Marker PC0 (PF0 on the 2560) toggles just before the first timer starts and
 * just after the last one stops.
 *
 * Then Timer1 alone: CTC, OCR1A = 0, clk/1, interrupt OCIE1A enabled with
 * OCR1A still 0 (the grbl stepper pattern); the ISR sets OCR1A = 1999 on its
 * first run and counts its runs in `isr_count`; from then on OCF1A comes every
 * 2000 cycles (OC1A toggling there too, COM1A = 01). `ocr_at_first_isr` is
 * OCR1A as the first ISR found it (0).
 */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t isr_count;
volatile uint16_t ocr_at_first_isr = 0xFFFF;
volatile uint8_t phase;

ISR(TIMER1_COMPA_vect)
{
    if (isr_count == 0) {
        ocr_at_first_isr = OCR1A;
        OCR1A = 1999;
    }
    if (isr_count != 0xFF) ++isr_count;
}

int main(void)
{
    tmr_oc_outputs();
    /* Phase 1: every timer toggles OCnA on every cycle. */
    MARK_TOGGLE(0);
#if TMR_MODERN
    TCCR0A = _BV(COM0A0) | _BV(WGM01);
    TCCR0B = _BV(CS00);
    TCCR1A = _BV(COM1A0);
    TCCR1B = _BV(WGM12) | _BV(CS10);
    TCCR2A = _BV(COM2A0) | _BV(WGM21);
    TCCR2B = _BV(CS20);
#if TMR_SIX
    TCCR3A = _BV(COM3A0);
    TCCR3B = _BV(WGM32) | _BV(CS30);
    TCCR4A = _BV(COM4A0);
    TCCR4B = _BV(WGM42) | _BV(CS40);
    TCCR5A = _BV(COM5A0);
    TCCR5B = _BV(WGM52) | _BV(CS50);
#endif
    __builtin_avr_delay_cycles(200);
    TCCR0B = 0;
    TCCR1B = _BV(WGM12);
    TCCR2B = 0;
#if TMR_SIX
    TCCR3B = 0;
    TCCR4B = 0;
    TCCR5B = 0;
#endif
#else
    TCCR0 = _BV(WGM01) | _BV(COM00) | _BV(CS00);
    TCCR1A = _BV(COM1A0);
    TCCR1B = _BV(WGM12) | _BV(CS10);
    TCCR2 = _BV(WGM21) | _BV(COM20) | _BV(CS20);
    __builtin_avr_delay_cycles(200);
    TCCR0 = 0;
    TCCR1B = _BV(WGM12);
    TCCR2 = 0;
#endif
    MARK_TOGGLE(0);
    phase = 1;

    /* Phase 2: Timer1's interrupt enabled while OCR1A is still 0. */
    __builtin_avr_delay_cycles(100);
    /* TCNT1 is 0 (CTC with TOP = 0). Not written: a TCNT1 write would block
     * the compare match of the next timer clock, and with it this TOP (§16.7.3). */
#if TMR_MODERN
    TIFR1 = _BV(OCF1A);
    TIMSK1 = _BV(OCIE1A);
#else
    TIFR = _BV(OCF1A);
    TIMSK = _BV(OCIE1A);
#endif
    sei();
    MARK_TOGGLE(1);
    TCCR1B = _BV(WGM12) | _BV(CS10);
    for (;;) {
    }
}
