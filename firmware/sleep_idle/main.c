/*
 * sleep_idle - sleeps in IDLE mode, woken every 10 ms by Timer1.
 *
 * The CPU does nothing but SLEEP; each Timer1 compare match wakes it, the ISR
 * toggles PB5 (UNO D13) and counts the wake-up in `wakeups`, and the CPU goes
 * back to sleep. A bench with virtual time must run this at the same speed
 * (in simulated cycles) as a busy loop and must not wait on the wall clock.
 *
 * Period: (OCR1A + 1) * N = (19999 + 1) * 8 = 160000 CPU cycles between
 * compare matches = 10.000 ms at 16 MHz; PB5 is a 50 Hz square wave (period
 * 20 ms = 320000 cycles) and `wakeups` grows by 100 per simulated second.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

/* Global (not static) so the symbol is in the ELF for the bench to read. */
volatile uint16_t wakeups;

ISR(TIMER1_COMPA_vect)
{
    PINB = _BV(PB5); /* writing one to PINxn toggles PORTxn */
    wakeups++;
}

int main(void)
{
    DDRB = _BV(PB5);

    /* TOP = OCR1A = 19999 -> 20000 counts of clk/8. 16 MHz / 8 = 2 MHz timer
     * clock, so 20000 counts = 10 ms; still fits 16 bits (max 65535). */
    OCR1A = 19999;
    TCCR1A = 0;              /* OC1A/OC1B disconnected, WGM11:10 = 00 */
    TIMSK1 = _BV(OCIE1A);    /* interrupt on compare match A */
    TCNT1 = 0;
    GTCCR = _BV(PSRSYNC);    /* start from a fresh prescaler period */
    /* WGM12 = 1 -> mode 4 (CTC, TOP = OCR1A); CS12:0 = 010 -> clk_I/O / 8.
     * Last, because a non-zero clock select starts the timer. */
    TCCR1B = _BV(WGM12) | _BV(CS11);

    /* SM2:0 = 000, Idle: clk_CPU stops, clk_I/O keeps running, so Timer1
     * keeps counting and its interrupt wakes the CPU ("Power Management and
     * Sleep Modes"). SE is set once and left set: this program has no
     * reason to guard against an accidental SLEEP. */
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();
    sei();
    for (;;) {
        sleep_cpu();
    }
}
