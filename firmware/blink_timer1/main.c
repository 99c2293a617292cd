/*
 * blink_timer1 - Timer1 in CTC mode toggling two pins every 16000 CPU cycles.
 *
 * One pin is toggled by software (the compare-match ISR), the other by the
 * timer hardware itself (compare output mode), so a test can check both the
 * interrupt path and the waveform generator against the same period.
 *
 *                      ATmega328P (UNO)     ATmega2560 (Mega)
 *   ISR toggled LED    PB5 (D13)            PB7 (D13)
 *   OC1A (hardware)    PB1 (D9)             PB5 (D11)
 *
 * Period: (OCR1A + 1) * N = (249 + 1) * 64 = 16000 CPU cycles between toggles
 * of each pin, i.e. a square wave of period 32000 cycles:
 *   16 MHz: toggle every 1.000 ms, 500 Hz square wave
 *   20 MHz: toggle every 0.800 ms, 625 Hz square wave
 * (datasheet formula for CTC: f_OC1A = f_clk / (2 * N * (1 + OCR1A))).
 *
 * Built as blink_timer1, blink_timer1_20mhz, blink_timer1_nommcu and
 * blink_timer1_m2560 (see firmware/CMakeLists.txt).
 */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#if defined(__AVR_ATmega2560__)
#define LED_BIT  PB7 /* Arduino Mega "D13" LED */
#define OC1A_BIT PB5 /* 2560 pinout: PB5 = OC1A/PCINT5 */
#elif defined(__AVR_ATmega328P__)
#define LED_BIT  PB5 /* Arduino UNO "D13" LED */
#define OC1A_BIT PB1 /* 328P pinout: PB1 = OC1A/PCINT1 */
#else
#error "blink_timer1: pin map only for atmega328p and atmega2560"
#endif

/* Compare match A: the interrupt flag OCF1A is set when TCNT1 reaches OCR1A
 * (which in CTC mode is also the moment TCNT1 is cleared), and is cleared by
 * hardware when this vector executes. */
ISR(TIMER1_COMPA_vect)
{
    /* Writing a one to PINxn toggles PORTxn ("Toggling the Pin" in I/O
     * Ports). A plain store (out), not PINB |= ..., because sbi on PINB is a
     * read-modify-write in simavr and would also toggle every other pin of
     * port B that currently reads high (OC1A among them). */
    PINB = _BV(LED_BIT);
}

/* The compare value; blink_timer1_ocr250 is built with 250 to show a
 * regression that shifts the timing (one timer count = 64 cycles per period). */
#ifndef BLINK_OCR1A
#define BLINK_OCR1A 249
#endif

int main(void)
{
    /* Both pins as outputs. For OC1A the datasheet requires the DDR bit set:
     * the compare output unit overrides PORTB1 (PB5 on the 2560) only while
     * the pin's output driver is enabled. */
    DDRB = _BV(LED_BIT) | _BV(OC1A_BIT);

    /* TOP = OCR1A = 249 -> 250 timer counts per period. Written before the
     * clock starts, so the first period is already a full one. */
    OCR1A = BLINK_OCR1A;

    /* TCCR1A: COM1A1:0 = 01 -> "Toggle OC1A on Compare Match" (Compare Output
     * Mode, non-PWM). WGM11:10 = 00; together with WGM13:12 = 01 in TCCR1B
     * this selects mode 4, CTC with TOP = OCR1A (Waveform Generation Mode
     * table). */
    TCCR1A = _BV(COM1A0);

    /* OCIE1A: interrupt on compare match A. */
    TIMSK1 = _BV(OCIE1A);

    /* Start counting from 0 and from the start of a prescaler period, so the
     * first compare match is exactly 250 * 64 = 16000 cycles after the clock
     * select below. PSRSYNC resets the (shared Timer0/Timer1) prescaler and
     * is cleared by hardware; without it the first period would be short by
     * up to 63 cycles on real silicon. */
    TCNT1 = 0;
    GTCCR = _BV(PSRSYNC);

    /* TCCR1B: WGM12 = 1 (mode 4, CTC), CS12:0 = 011 -> clk_I/O / 64 (Clock
     * Select table). Writing a non-zero clock select starts the timer, so
     * this is the last register written. */
    TCCR1B = _BV(WGM12) | _BV(CS11) | _BV(CS10);

    sei();
    for (;;) {
    }
}
