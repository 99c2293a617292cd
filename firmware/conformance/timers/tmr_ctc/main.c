/*
 * tmr_ctc - every Timer/Counter in CTC mode, OCnA toggling on compare match
 * (COMnA1:0 = 01), all running at once.
 *
 * Datasheet: in CTC mode the counter is cleared when it matches OCRnA, so
 * OCnA toggles every (OCRnA + 1) * N CPU cycles (ATmega328P §15.7.2, §16.9.2,
 * §18.7.2: f_OCnA = f_clk / (2 N (1 + OCRnA))); TOVn is set only when the
 * counter passes MAX, which never happens here since TCNTn <= OCRnA.
 *
 *   timer  N     OCRnA   toggle interval (cycles)
 *   0      8     99      800
 *   1      1     1233    1234
 *   2      32    49      1600   (Timer2's own prescaler has clk/32)
 *   3      1     2999    3000   (2560)
 *   4      64    99      6400   (2560)
 *   5      1     4095    4096   (2560)
 *
 * Globals: tov_seen / ocf_seen, bit n set once TOVn / OCFnA was seen set
 * (polled; no interrupts enabled).
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t tov_seen;
volatile uint8_t ocf_seen;

int main(void)
{
    tmr_oc_outputs();
#if TMR_MODERN
    OCR0A = 99;
    TCCR0A = _BV(COM0A0) | _BV(WGM01); /* mode 2: CTC */
    OCR1A = 1233;
    TCCR1A = _BV(COM1A0);              /* WGM13:0 = 0100 with WGM12 below */
    OCR2A = 49;
    TCCR2A = _BV(COM2A0) | _BV(WGM21);
#if TMR_SIX
    OCR3A = 2999;
    TCCR3A = _BV(COM3A0);
    OCR4A = 99;
    TCCR4A = _BV(COM4A0);
    OCR5A = 4095;
    TCCR5A = _BV(COM5A0);
#endif
    TCCR0B = _BV(CS01);                          /* clk/8 */
    TCCR1B = _BV(WGM12) | _BV(CS10);             /* clk/1 */
    TCCR2B = _BV(CS21) | _BV(CS20);              /* clk/32 */
#if TMR_SIX
    TCCR3B = _BV(WGM32) | _BV(CS30);             /* clk/1 */
    TCCR4B = _BV(WGM42) | _BV(CS41) | _BV(CS40); /* clk/64 */
    TCCR5B = _BV(WGM52) | _BV(CS50);             /* clk/1 */
#endif
#else
    OCR0 = 99;
    TCCR0 = _BV(WGM01) | _BV(COM00) | _BV(CS01);            /* CTC, toggle OC0, clk/8 */
    OCR1A = 1233;
    TCCR1A = _BV(COM1A0);
    TCCR1B = _BV(WGM12) | _BV(CS10);
    OCR2 = 49;
    TCCR2 = _BV(WGM21) | _BV(COM20) | _BV(CS21) | _BV(CS20); /* CTC, toggle OC2, clk/32 */
#endif

    for (;;) {
#if TMR_MODERN
        if (TIFR0 & _BV(TOV0)) tov_seen |= 1;
        if (TIFR1 & _BV(TOV1)) tov_seen |= 2;
        if (TIFR2 & _BV(TOV2)) tov_seen |= 4;
        if (TIFR0 & _BV(OCF0A)) ocf_seen |= 1;
        if (TIFR1 & _BV(OCF1A)) ocf_seen |= 2;
        if (TIFR2 & _BV(OCF2A)) ocf_seen |= 4;
#if TMR_SIX
        if (TIFR3 & _BV(TOV3)) tov_seen |= 8;
        if (TIFR4 & _BV(TOV4)) tov_seen |= 16;
        if (TIFR5 & _BV(TOV5)) tov_seen |= 32;
        if (TIFR3 & _BV(OCF3A)) ocf_seen |= 8;
        if (TIFR4 & _BV(OCF4A)) ocf_seen |= 16;
        if (TIFR5 & _BV(OCF5A)) ocf_seen |= 32;
#endif
#else
        const uint8_t f = TIFR;
        if (f & _BV(TOV0)) tov_seen |= 1;
        if (f & _BV(TOV1)) tov_seen |= 2;
        if (f & _BV(TOV2)) tov_seen |= 4;
        if (f & _BV(OCF0)) ocf_seen |= 1;
        if (f & _BV(OCF1A)) ocf_seen |= 2;
        if (f & _BV(OCF2)) ocf_seen |= 4;
#endif
    }
}
