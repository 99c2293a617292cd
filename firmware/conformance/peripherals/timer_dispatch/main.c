/*
 * timer_dispatch - a software-timer dispatcher the way Klipper's AVR code
 * runs one (src/avr/timer.c, src/sched.c), reduced to what the hardware sees:
 * no compare match may be lost or served late because the main line waits in
 * `sei; nop; cli`.
 *
 * ATmega328P §7.7 / ATmega2560 §7.8 / ATmega32 "Interrupt Response Time":
 * "When using the SEI instruction to enable interrupts, the instruction
 * following SEI will be executed before any pending interrupts"; after that
 * one instruction a pending enabled interrupt is served. So an interrupt
 * whose flag is set while the NOP of `sei; nop; cli` runs - with nothing
 * pending when SEI ran - is served before the CLI. (simavr 1.6 serves a
 * pending interrupt only after the second instruction following SEI: the
 * CLI clears I first, and the flag stays pending, unserved, until something
 * else raises an interrupt while I = 0. Klipper shuts down 0.4 s after every
 * reset because of it: "Rescheduled timer in the past".)
 *
 * The firmware:
 *  - Timer1 in Normal mode at clk/1 (TCCR1A = 0, TCCR1B = CS10), the OCR1A
 *    compare interrupt; the ISR dispatches the "timers" due, each PERIOD
 *    cycles after the last, and reprograms OCR1A from inside itself to the
 *    next due time, which may already be near or past: then it opens a
 *    one-instruction interrupt window (sei; nop; cli) for the serial port
 *    and dispatches again, as Klipper's does;
 *  - OCR1B as Klipper's repeat limit: set to now + 3000 on entry, its flag
 *    OCF1B polled (never enabled), cleared by writing one with OUT;
 *  - the main line waits in `sei; nop; cli`, polls TOV1 and clears it with
 *    OUT (Klipper's timer_read_time/timer_event: a 32-bit clock from the
 *    16-bit counter);
 *  - USART0 at 250000 baud with U2X (UBRR = 7), 8N1: every 64th dispatch
 *    enables the UDRE interrupt, which sends four bytes and disables itself
 *    (Klipper answers a host now and then; the interrupt nests in the
 *    dispatcher's windows). In between the line is quiet, as Klipper's is
 *    with no host: nothing but the timer raises an interrupt.
 *
 * Recorded: `served` (dispatches), `max_late` (the most cycles a dispatch
 * started after its due time, TCNT1 - due), `wraps` (TOV1 seen by the main
 * line), `sent` (bytes out). The test checks every due time was served and
 * none late by more than the longest stretch the firmware keeps interrupts
 * off (hand count in the test).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#if defined(TIMSK1)
#define TIMSK_T1 TIMSK1
#define TIFR_T1 TIFR1
#else
#define TIMSK_T1 TIMSK
#define TIFR_T1 TIFR
#endif

#if defined(__AVR_ATmega32__)
#define UDRn UDR
#define UCSRnA UCSRA
#define UCSRnB UCSRB
#define UBRRnL UBRRL
#define U2Xn U2X
#define TXENn TXEN
#define UDRIEn UDRIE
#define UDRE_VECT USART_UDRE_vect
#define SET_8N1() (UCSRC = (uint8_t)((1 << URSEL) | (1 << UCSZ1) | (1 << UCSZ0)))
#else
#define UDRn UDR0
#define UCSRnA UCSR0A
#define UCSRnB UCSR0B
#define UBRRnL UBRR0L
#define U2Xn U2X0
#define TXENn TXEN0
#define UDRIEn UDRIE0
#if defined(__AVR_ATmega2560__)
#define UDRE_VECT USART0_UDRE_vect
#else
#define UDRE_VECT USART_UDRE_vect
#endif
#define SET_8N1() (UCSR0C = (uint8_t)((1 << UCSZ01) | (1 << UCSZ00)))
#endif

/* 1000 cycles: not a multiple of the main loop's length, so the matches land
 * on every instruction of it, the NOP of `sei; nop; cli` among them. */
#define PERIOD 1000u
#define REPEAT_TICKS 3000u /* Klipper's TIMER_REPEAT_TICKS */

volatile uint16_t due;       /* the next dispatch's due time, TCNT1 cycles */
volatile uint32_t served;
volatile uint16_t max_late;
volatile uint16_t wraps;
volatile uint16_t sent;
volatile uint8_t started;

/* `TIFRn = _BV(bit)` with OUT, as Klipper writes it (TIFR1 is an I/O register). */
#define CLEAR_FLAG_OUT(bit) \
    __asm__ __volatile__("out %0, %1" ::"I"(_SFR_IO_ADDR(TIFR_T1)), "r"((uint8_t)_BV(bit)) : "memory")

ISR(TIMER1_COMPA_vect)
{
    OCR1B = (uint16_t)(TCNT1 + REPEAT_TICKS);
    CLEAR_FLAG_OUT(OCF1B);
    for (;;) {
        const uint16_t late = (uint16_t)(TCNT1 - due);
        if ((int16_t)late >= 0 && late > max_late) max_late = late;
        served++;
        if ((served & 63) == 0) UCSRnB |= _BV(UDRIEn);
        due = (uint16_t)(due + PERIOD);
        const int16_t diff = (int16_t)(TCNT1 - due);
        if (diff < -100) break;                   /* not due soon: program the compare */
        __asm__ __volatile__("sei\n\tnop\n\tcli" ::: "memory"); /* let the serial port in */
        if (TIFR_T1 & _BV(OCF1B)) break;          /* too many in a row (never here) */
        while ((int16_t)(TCNT1 - due) < 0) {
        }
    }
    OCR1A = due;
}

ISR(UDRE_VECT)
{
    UDRn = (uint8_t)('A' + (sent & 15));
    sent++;
    if ((sent & 3) == 0) UCSRnB &= (uint8_t)~_BV(UDRIEn);
}

int main(void)
{
    UBRRnL = 7; /* 250000 baud with U2X: 16 MHz / (8 * 250000) - 1 */
    UCSRnA = _BV(U2Xn);
    SET_8N1();
    UCSRnB = _BV(TXENn);

    TCCR1A = 0;
    TCNT1 = 0;
    due = PERIOD;
    OCR1A = PERIOD;
    TIFR_T1 = _BV(OCF1A) | _BV(OCF1B) | _BV(TOV1);
    TIMSK_T1 = _BV(OCIE1A);
    TCCR1B = _BV(CS10);
    started = 1;
    for (;;) {
        __asm__ __volatile__("sei\n\tnop\n\tcli" ::: "memory"); /* Klipper's irq_wait() */
        if (TIFR_T1 & _BV(TOV1)) {
            CLEAR_FLAG_OUT(TOV1);
            wraps++;
        }
    }
}
