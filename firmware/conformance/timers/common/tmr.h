/*
 * tmr.h - what differs between the parts the timer conformance firmware runs
 * on (ATmega328P, ATmega2560, ATmega32), so one source builds for all.
 *
 *   TMR_MODERN     1 on the 328P/2560 (TCCRnA/B, TIMSKn, TIFRn per timer),
 *                  0 on the ATmega32 (TCCR0, TCCR2, shared TIMSK/TIFR)
 *   TMR_SIX        1 on the 2560 (Timer/Counter3, 4, 5)
 *   tmr_oc_outputs()  makes every OCnx pin an output (DDR bits), low
 *
 * OCnx pins (datasheet pin configurations / "Alternate Port Functions"):
 *   328P: OC0A PD6, OC0B PD5, OC1A PB1, OC1B PB2, OC2A PB3, OC2B PD3, ICP1 PB0
 *   2560: OC0A PB7, OC0B PG5, OC1A PB5, OC1B PB6, OC1C PB7, OC2A PB4, OC2B PH6,
 *         OC3A/B/C PE3/4/5, OC4A/B/C PH3/4/5, OC5A/B/C PL3/4/5, ICP1 PD4
 *   m32:  OC0 PB3, OC1A PD5, OC1B PD4, OC2 PD7, ICP1 PD6
 *
 * Marker pins (edges the tests use as time references) are on a port of
 * their own: PC0..PC3 (328P, m32) / PF0..PF3 (2560), written with OUT/SBI/CBI.
 */
#ifndef TMR_H
#define TMR_H

#include <avr/io.h>

#if defined(TCCR0A)
#define TMR_MODERN 1
#else
#define TMR_MODERN 0
#endif

#if defined(TCCR5A)
#define TMR_SIX 1
#else
#define TMR_SIX 0
#endif

#if defined(__AVR_ATmega2560__)
#define MARK_PORT PORTF
#define MARK_DDR DDRF
#define MARK_PIN PINF
#else
#define MARK_PORT PORTC
#define MARK_DDR DDRC
#define MARK_PIN PINC
#endif

static inline void tmr_oc_outputs(void)
{
#if defined(__AVR_ATmega328P__)
    DDRB |= _BV(1) | _BV(2) | _BV(3);
    DDRD |= _BV(3) | _BV(5) | _BV(6);
#elif defined(__AVR_ATmega2560__)
    DDRB |= _BV(4) | _BV(5) | _BV(6) | _BV(7);
    DDRE |= _BV(3) | _BV(4) | _BV(5);
    DDRG |= _BV(5);
    DDRH |= _BV(3) | _BV(4) | _BV(5) | _BV(6);
    DDRL |= _BV(3) | _BV(4) | _BV(5);
#elif defined(__AVR_ATmega32__)
    DDRB |= _BV(3);
    DDRD |= _BV(4) | _BV(5) | _BV(7);
#else
#error "tmr.h: pin map only for atmega328p, atmega2560, atmega32"
#endif
    MARK_DDR = 0x0F;
}

/* Marker edges: OUT to the PIN register toggles (328P/2560); the ATmega32
 * has no PIN toggle, so markers there are written to PORT. */
#if TMR_MODERN
#define MARK_TOGGLE(bit) (MARK_PIN = _BV(bit))
#else
#define MARK_TOGGLE(bit) (MARK_PORT ^= _BV(bit))
#endif

#endif
