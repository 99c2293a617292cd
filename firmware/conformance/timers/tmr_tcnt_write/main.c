/*
 * tmr_tcnt_write - writing TCNTn.
 *
 * Datasheet (ATmega328P §16.7.2 "Compare Match Blocking by TCNT1 Write",
 * §15.5.2 for TCNT0; §16.11.4 "TCNT1H and TCNT1L"): "All CPU
 * write operations to the TCNT1 Register will block any compare match that
 * occurs in the next timer clock cycle, even when the timer is stopped. This
 * feature allows OCR1A to be initialized to the same value as TCNT1 without
 * triggering an interrupt when the Timer/Counter clock is enabled." The
 * counter continues from the value written, stopped or running.
 *
 * Timer1 (and Timer0) in Normal mode at clk/1, OCRnA = 1000 (100 for Timer0);
 * `r[]`, 1 = the flag was set, 0 = not:
 *   [0] TCNT1 = 0xFFF0 before the timer ever ran, start, 100 cycles: TOV1 = 1
 *   [1] TCNT1 = 1000 (= OCR1A) while stopped, start, 50 cycles: OCF1A = 0
 *   [2] TCNT1 = 999 while stopped, start, 50 cycles:             OCF1A = 1
 *   [3] TCNT1 = 1000 while running, 50 cycles:                    OCF1A = 0
 *   [4..7] the same for Timer0 (TCNT0 = 0xF0; 100; 99; 100)       1, 0, 1, 0
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t r[8];
volatile uint8_t done;

#if TMR_MODERN
#define FLAGS1 TIFR1
#define FLAGS0 TIFR0
#define CONTROL0 TCCR0B
#define OCR0 OCR0A
#define OCF0 OCF0A
#else
#define FLAGS1 TIFR
#define FLAGS0 TIFR
#define CONTROL0 TCCR0
#endif

#define CHECK(flags, bit) (((flags) & _BV(bit)) ? 1 : 0)

int main(void)
{
    OCR1A = 1000;
    TCNT1 = 0xFFF0;
    FLAGS1 = 0xFF;
    TCCR1B = _BV(CS10);
    __builtin_avr_delay_cycles(100);
    r[0] = CHECK(FLAGS1, TOV1);

    TCCR1B = 0;
    TCNT1 = 1000;
    FLAGS1 = 0xFF;
    TCCR1B = _BV(CS10);
    __builtin_avr_delay_cycles(50);
    r[1] = CHECK(FLAGS1, OCF1A);

    TCCR1B = 0;
    TCNT1 = 999;
    FLAGS1 = 0xFF;
    TCCR1B = _BV(CS10);
    __builtin_avr_delay_cycles(50);
    r[2] = CHECK(FLAGS1, OCF1A);

    FLAGS1 = 0xFF;
    TCNT1 = 1000;
    __builtin_avr_delay_cycles(50);
    r[3] = CHECK(FLAGS1, OCF1A);
    TCCR1B = 0;

    OCR0 = 100;
    TCNT0 = 0xF0;
    FLAGS0 = 0xFF;
    CONTROL0 = _BV(CS00);
    __builtin_avr_delay_cycles(100);
    r[4] = CHECK(FLAGS0, TOV0);

    CONTROL0 = 0;
    TCNT0 = 100;
    FLAGS0 = 0xFF;
    CONTROL0 = _BV(CS00);
    __builtin_avr_delay_cycles(50);
    r[5] = CHECK(FLAGS0, OCF0);

    CONTROL0 = 0;
    TCNT0 = 99;
    FLAGS0 = 0xFF;
    CONTROL0 = _BV(CS00);
    __builtin_avr_delay_cycles(50);
    r[6] = CHECK(FLAGS0, OCF0);

    FLAGS0 = 0xFF;
    TCNT0 = 100;
    __builtin_avr_delay_cycles(50);
    r[7] = CHECK(FLAGS0, OCF0);
    CONTROL0 = 0;

    done = 1;
    for (;;) {
    }
}
