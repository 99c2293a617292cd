/*
 * tmr_ctc_rewrite - CTC mode, OCRnA rewritten below the running TCNTn.
 *
 * Datasheet (ATmega328P §16.9.2, same words in §15.7.2/§18.7.2): "If the new
 * value written to OCR1A or ICR1 is lower than the current value of TCNT1,
 * the counter will miss the compare match. The counter will then have to
 * count to its maximum value (0xFFFF) and wrap around starting at 0x0000
 * before the compare match can occur."
 *
 * Each timer: CTC, clk/1, OCnA toggling (COMnA = 01), OCRnA = OLD; after two
 * matches the firmware waits until TCNTn >= MID and writes OCRnA = NEW < MID.
 * The toggle interval is then OLD+1, ..., OLD+1, MAX+1 + NEW+1, NEW+1, ...
 *
 *   timer   OLD   MID   NEW   interval across the rewrite
 *   1,3-5   999   500   99    65536 + 100 = 65636
 *   0, 2    199   150   49    256 + 50 = 306
 *
 * `tov_at_match`: bit n set when TOVn was already set at the first compare
 * match after the rewrite (it must be: the counter passed MAX).
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t tov_at_match;
volatile uint8_t done;

/* Waits for two matches of the old value, then rewrites OCRnA below TCNTn. */
#define REWRITE(tcnt, ocr, flags, ocf, mid, value)  \
    do {                                            \
        for (uint8_t k = 0; k < 2; ++k) {           \
            flags = _BV(ocf);                       \
            while (!(flags & _BV(ocf))) {           \
            }                                       \
        }                                           \
        flags = _BV(ocf);                           \
        while (tcnt < (mid)) {                      \
        }                                           \
        ocr = (value);                              \
    } while (0)

/* The first match after the rewrite: was TOVn set by then? */
#define AWAIT(flags, ocf, tov, bit)                 \
    do {                                            \
        while (!(flags & _BV(ocf))) {               \
        }                                           \
        if (flags & _BV(tov)) tov_at_match |= (bit); \
    } while (0)

int main(void)
{
    tmr_oc_outputs();
#if TMR_MODERN
    OCR0A = 199;
    TCCR0A = _BV(COM0A0) | _BV(WGM01);
    OCR1A = 999;
    TCCR1A = _BV(COM1A0);
    OCR2A = 199;
    TCCR2A = _BV(COM2A0) | _BV(WGM21);
    TCCR0B = _BV(CS00);
    TCCR1B = _BV(WGM12) | _BV(CS10);
    TCCR2B = _BV(CS20);
#if TMR_SIX
    OCR3A = 999;
    TCCR3A = _BV(COM3A0);
    OCR4A = 999;
    TCCR4A = _BV(COM4A0);
    OCR5A = 999;
    TCCR5A = _BV(COM5A0);
    TCCR3B = _BV(WGM32) | _BV(CS30);
    TCCR4B = _BV(WGM42) | _BV(CS40);
    TCCR5B = _BV(WGM52) | _BV(CS50);
#endif
    REWRITE(TCNT1, OCR1A, TIFR1, OCF1A, 500, 99);
    REWRITE(TCNT0, OCR0A, TIFR0, OCF0A, 150, 49);
    REWRITE(TCNT2, OCR2A, TIFR2, OCF2A, 150, 49);
#if TMR_SIX
    REWRITE(TCNT3, OCR3A, TIFR3, OCF3A, 500, 99);
    REWRITE(TCNT4, OCR4A, TIFR4, OCF4A, 500, 99);
    REWRITE(TCNT5, OCR5A, TIFR5, OCF5A, 500, 99);
#endif
    AWAIT(TIFR0, OCF0A, TOV0, 0x01);
    AWAIT(TIFR2, OCF2A, TOV2, 0x04);
    AWAIT(TIFR1, OCF1A, TOV1, 0x02);
#if TMR_SIX
    AWAIT(TIFR3, OCF3A, TOV3, 0x08);
    AWAIT(TIFR4, OCF4A, TOV4, 0x10);
    AWAIT(TIFR5, OCF5A, TOV5, 0x20);
#endif
#else
    OCR0 = 199;
    TCCR0 = _BV(WGM01) | _BV(COM00) | _BV(CS00);
    OCR1A = 999;
    TCCR1A = _BV(COM1A0);
    TCCR1B = _BV(WGM12) | _BV(CS10);
    OCR2 = 199;
    TCCR2 = _BV(WGM21) | _BV(COM20) | _BV(CS20);
    REWRITE(TCNT1, OCR1A, TIFR, OCF1A, 500, 99);
    REWRITE(TCNT0, OCR0, TIFR, OCF0, 150, 49);
    REWRITE(TCNT2, OCR2, TIFR, OCF2, 150, 49);
    AWAIT(TIFR, OCF0, TOV0, 0x01);
    AWAIT(TIFR, OCF2, TOV2, 0x04);
    AWAIT(TIFR, OCF1A, TOV1, 0x02);
#endif
    done = 1;
    for (;;) {
    }
}
