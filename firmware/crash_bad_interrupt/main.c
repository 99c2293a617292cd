/*
 * crash_bad_interrupt - enables an interrupt that has no handler.
 *
 * Timer0 runs in normal mode at clk/1 with TOIE0 set and no
 * ISR(TIMER0_OVF_vect) in the program, so avr-libc's vector table points the
 * TIMER0_OVF vector (number 16, byte address 0x0040) at `__bad_interrupt`,
 * which jumps to `__vector_default` - by default the reset vector, address 0.
 * That is a restart *without* a hardware reset: I/O registers (Timer0 still
 * running, TOIE0 still set, PORTB) keep their values, .data/.bss are
 * re-initialised by the C start-up code.
 *
 * Timer0 overflows every 256 CPU cycles (TCNT0 counts 0..255 at clk/1, TOV0
 * set on the 255 -> 0 step). The first overflow after sei() vectors to
 * __bad_interrupt; after every restart main sets the same registers and
 * enables interrupts again, so the firmware restarts again on the next
 * overflow and PB5 (toggled once at each start) toggles on every restart.
 */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

int main(void)
{
    DDRB = _BV(PB5);
    PINB = _BV(PB5); /* the one start-up toggle (per restart) */

    /* TCCR0A: WGM01:00 = 00 and TCCR0B WGM02 = 0 -> normal mode, TOP = 0xFF;
     * COM0x = 00, OC0A/OC0B disconnected. */
    TCCR0A = 0;
    /* TOIE0: Timer/Counter0 overflow interrupt enable. */
    TIMSK0 = _BV(TOIE0);
    /* CS02:0 = 001 -> clk_I/O, no prescaling. Starts the timer. */
    TCCR0B = _BV(CS00);

    sei();
    for (;;) {
    }
}
