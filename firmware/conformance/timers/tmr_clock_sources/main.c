/*
 * tmr_clock_sources (ATmega328P) - Timer/Counter2 from the 32.768 kHz
 * crystal, Timer/Counter1 from its T1 pin.
 *
 * Datasheet §18.9 "Asynchronous Operation of Timer/Counter2" (ASSR.AS2 = 1:
 * "Timer/Counter2 is clocked from a crystal Oscillator connected to the Timer
 * Oscillator 1 (TOSC1) pin"); §17.3 "External Clock Source": CS12:0 = 111
 * clocks Timer/Counter1 on the rising edge of T1 (PD5).
 *  - Timer2: AS2 = 1, Normal mode, clk_T2S/1, OC2A (PB3) toggling on OCR2A = 10:
 *    every 256 crystal periods = 256 * 16 MHz / 32768 Hz = 125000 CPU cycles.
 *  - Timer1: CTC, OCR1A = 9, CS12:0 = 111, OC1A (PB1) toggling every 10 rising
 *    edges on T1 (PD5, driven by the bench); `tcnt1` = TCNT1, copied forever.
 */
#include <avr/io.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t tcnt1;

int main(void)
{
    DDRB = _BV(1) | _BV(3);
    ASSR = _BV(AS2);
    OCR2A = 10;
    TCCR2A = _BV(COM2A0);
    TCCR2B = _BV(CS20);
    OCR1A = 9;
    TCCR1A = _BV(COM1A0);
    TCCR1B = _BV(WGM12) | _BV(CS12) | _BV(CS11) | _BV(CS10);
    for (;;) {
        tcnt1 = TCNT1;
    }
}
