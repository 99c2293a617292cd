/*
 * tmr_phase_correct - phase correct (and phase and frequency correct) PWM:
 * period, duty, OCRnx = BOTTOM and TOP, inverting output, COMnA = 01 toggle
 * with OCRnA as TOP, and the double buffer of OCRnx (updated at TOP).
 *
 * Datasheet (ATmega328P §15.7.4 / §16.9.4 / §16.9.5 / §18.7.4, Tables 15-4,
 * 16-3, 18-4): dual slope, BOTTOM -> TOP -> BOTTOM, 2 * TOP timer clocks per
 * period (f = f_clk / (N * 510) for TOP = 0xFF); COMnx = 10 clears OCnx on the
 * match while up-counting and sets it while down-counting: high for
 * 2 * OCRnx clocks around BOTTOM; "If the OCR0A register is written equal to
 * BOTTOM, the output will be continuously low. If OCR0A is written to MAX, the
 * output will be continuously high for non-inverted PWM mode."
 *
 * All at clk/1.
 *   328P/2560 Timer0 mode 1 (TOP 0xFF): OC0A COM=10 OCR0A=0   continuously low
 *                                       OC0B COM=10 OCR0B=255 continuously high
 *   328P/2560 Timer2 mode 1:            OC2A COM=10 OCR2A=64  high 128 of 510
 *                                       OC2B COM=11 OCR2B=64  low 128 of 510
 *   all Timer1 mode 10 (TOP ICR1=500):  OC1A COM=10 OCR1A=100 high 200 of 1000
 *                                       OC1B COM=10 OCR1B=500 (TOP) continuously high
 *   2560 Timer3 mode 8 (phase and frequency correct, TOP ICR3=300):
 *                                       OC3A COM=10 OCR3A=150 high 300 of 600
 *   2560 Timer4 mode 11 (TOP OCR4A=200): OC4A COM=01 toggles at TOP, every 400
 *                                       OC4B COM=10 OCR4B=50  high 100 of 400
 *   2560 Timer5 mode 1 (TOP 0xFF):      OC5A COM=10 OCR5A=128 high 256 of 510
 *   m32 Timer0 (WGM01:0 = 01):          OC0  COM=10 OCR0=64   high 128 of 510
 *   m32 Timer2:                         OC2  COM=10 OCR2=0    continuously low
 *
 * Double buffer: once running, the firmware waits for ICF1 (set at TOP), then
 * for TCNT1 <= 200 on the way down, and writes OCR1A = 400. The old 100 is
 * still used until the next TOP: high 200, 200, ..., then 800 (2 * 400);
 * low 800, ..., 500 (from 100 up to 400 down: 400 + 100), then 200.
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t phase;

#if TMR_MODERN
#define TIFR_T1 TIFR1
#else
#define TIFR_T1 TIFR
#endif

int main(void)
{
    tmr_oc_outputs();
    ICR1 = 500;
    OCR1A = 100;
    OCR1B = 500;
    TCCR1A = _BV(COM1A1) | _BV(COM1B1) | _BV(WGM11);
#if TMR_MODERN
    OCR0A = 0;
    OCR0B = 255;
    TCCR0A = _BV(COM0A1) | _BV(COM0B1) | _BV(WGM00);
    OCR2A = 64;
    OCR2B = 64;
    TCCR2A = _BV(COM2A1) | _BV(COM2B1) | _BV(COM2B0) | _BV(WGM20);
#if TMR_SIX
    ICR3 = 300;
    OCR3A = 150;
    TCCR3A = _BV(COM3A1);
    OCR4A = 200;
    OCR4B = 50;
    TCCR4A = _BV(COM4A0) | _BV(COM4B1) | _BV(WGM41) | _BV(WGM40);
    OCR5A = 128;
    TCCR5A = _BV(COM5A1) | _BV(WGM50);
#endif
    TCCR0B = _BV(CS00);
    TCCR1B = _BV(WGM13) | _BV(CS10);
    TCCR2B = _BV(CS20);
#if TMR_SIX
    TCCR3B = _BV(WGM33) | _BV(CS30);
    TCCR4B = _BV(WGM43) | _BV(CS40);
    TCCR5B = _BV(CS50);
#endif
#else
    OCR0 = 64;
    TCCR0 = _BV(WGM00) | _BV(COM01) | _BV(CS00);
    OCR2 = 0;
    TCCR2 = _BV(WGM20) | _BV(COM21) | _BV(CS20);
    TCCR1B = _BV(WGM13) | _BV(CS10);
#endif

    __builtin_avr_delay_cycles(6000);
    TIFR_T1 = _BV(ICF1);
    while (!(TIFR_T1 & _BV(ICF1))) {
    }
    while (TCNT1 > 200) {
    }
    OCR1A = 400;
    phase = 1;
    for (;;) {
    }
}
