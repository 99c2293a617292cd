/*
 * tmr_fast_pwm - fast PWM on every timer: duty cycles, OCRnx = BOTTOM and
 * TOP, inverting output, COMnA = 01 toggle with OCRnA as TOP, OCRnx above
 * TOP, and the double buffer of OCRnx (updated at BOTTOM).
 *
 * Datasheet (ATmega328P §15.7.3 / §16.9.3 / §18.7.3, Tables 15-3, 16-2, 18-3):
 * the counter counts BOTTOM..TOP, TOP+1 timer clocks per period; COMnx = 10
 * clears OCnx on compare match and sets it at BOTTOM (non-inverting: high for
 * OCRnx + 1 clocks), 11 the reverse; "If the OCR0A is set equal to BOTTOM, the
 * output will be a narrow spike for each MAX+1 timer clock cycle. Setting the
 * OCR0A equal to MAX will result in a constantly high or low output"; OCRnx
 * is double buffered and updated at BOTTOM (Table 15-8 "Update of OCRx at").
 *
 * All at clk/1 unless noted; "high" = cycles high per period.
 *   328P/2560 Timer0 mode 3 (TOP 0xFF): OC0A COM=10 OCR0A=0   high 1 of 256
 *                                       OC0B COM=10 OCR0B=63  high 64 of 256
 *   328P/2560 Timer2 mode 3:            OC2A COM=10 OCR2A=255 constantly high
 *                                       OC2B COM=11 OCR2B=191 low 192 of 256
 *   all Timer1 mode 14 (TOP ICR1=999):  OC1A COM=10 OCR1A=249 high 250 of 1000
 *                                       OC1B COM=10 OCR1B=0   high 1 of 1000
 *   2560 Timer3 mode 15 (TOP OCR3A=399): OC3A COM=01 toggles every 400
 *                                       OC3B COM=10 OCR3B=99  high 100 of 400
 *   2560 Timer4 mode 5 (TOP 0xFF):      OC4A COM=10 OCR4A=127 high 128 of 256
 *                                       OC4B COM=11 OCR4B=300 > TOP: no match, constantly low
 *   2560 Timer5 mode 7 (TOP 0x3FF):     OC5A COM=11 OCR5A=0x3FF (TOP) constantly low
 *                                       OC5B COM=10 OCR5B=511 high 512 of 1024
 *   m32 Timer0 (WGM01:0 = 11):          OC0  COM=10 OCR0=63   high 64 of 256
 *   m32 Timer2, clk/128 (the seed 001 heater PWM): OC2 COM=10, OCR2 = 0 for
 *       three periods, then 255 for three, then 127 (see README.md)
 *
 * Double buffer: once running, the firmware waits for TOV1 (BOTTOM), then for
 * TCNT1 >= 150 and writes OCR1A = 99: the period in progress still ends its
 * high phase at 250, the next ones at 100. `phase` = 1 after that write.
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
    ICR1 = 999;
    OCR1A = 249;
    OCR1B = 0;
    TCCR1A = _BV(COM1A1) | _BV(COM1B1) | _BV(WGM11);
#if TMR_MODERN
    OCR0A = 0;
    OCR0B = 63;
    TCCR0A = _BV(COM0A1) | _BV(COM0B1) | _BV(WGM01) | _BV(WGM00);
    OCR2A = 255;
    OCR2B = 191;
    TCCR2A = _BV(COM2A1) | _BV(COM2B1) | _BV(COM2B0) | _BV(WGM21) | _BV(WGM20);
#if TMR_SIX
    OCR3A = 399;
    OCR3B = 99;
    TCCR3A = _BV(COM3A0) | _BV(COM3B1) | _BV(WGM31) | _BV(WGM30);
    OCR4A = 127;
    OCR4B = 300;
    TCCR4A = _BV(COM4A1) | _BV(COM4B1) | _BV(COM4B0) | _BV(WGM40);
    OCR5A = 0x3FF;
    OCR5B = 511;
    TCCR5A = _BV(COM5A1) | _BV(COM5A0) | _BV(COM5B1) | _BV(WGM51) | _BV(WGM50);
#endif
    TCCR0B = _BV(CS00);
    TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS10);
    TCCR2B = _BV(CS20);
#if TMR_SIX
    TCCR3B = _BV(WGM33) | _BV(WGM32) | _BV(CS30);
    TCCR4B = _BV(WGM42) | _BV(CS40);
    TCCR5B = _BV(WGM52) | _BV(CS50);
#endif
#else
    OCR0 = 63;
    TCCR0 = _BV(WGM01) | _BV(WGM00) | _BV(COM01) | _BV(CS00);
    OCR2 = 0;
    TCCR2 = _BV(WGM21) | _BV(WGM20) | _BV(COM21) | _BV(CS22) | _BV(CS20); /* clk/128 */
    TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS10);
#endif

    /* OCR1A double buffer. */
    __builtin_avr_delay_cycles(5000);
    TIFR_T1 = _BV(TOV1);
    while (!(TIFR_T1 & _BV(TOV1))) {
    }
    while (TCNT1 < 150) {
    }
    OCR1A = 99;
    phase = 1;

#if !TMR_MODERN
    /* Timer2 at clk/128: OCR2 = 255 after the third TOV2, 127 after the sixth. */
    TIFR = _BV(TOV2);
    for (uint8_t n = 1; n <= 6; ++n) {
        while (!(TIFR & _BV(TOV2))) {
        }
        TIFR = _BV(TOV2);
        if (n == 3) OCR2 = 255;
        if (n == 6) OCR2 = 127;
    }
    phase = 2;
#endif
    for (;;) {
    }
}
