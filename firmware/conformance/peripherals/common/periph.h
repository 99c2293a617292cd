/*
 * periph.h - the few names that differ between the parts the peripheral
 * conformance firmware runs on (ATmega328P, ATmega2560, ATmega32), so that
 * one source builds for all three.
 *
 *   INT0_PIN/INT1_PIN  bit in PORTD/PIND of the INT0/INT1 pin
 *                      (328P, m32: PD2/PD3; 2560: PD0/PD1)
 *   EXT_SENSE          sense control register (EICRA; MCUCR on the m32)
 *   EXT_MASK           enable register (EIMSK; GICR on the m32)
 *   EXT_FLAGS          flag register (EIFR; GIFR on the m32)
 *   PUD_REG            register holding PUD (MCUCR; SFIOR on the m32)
 *   read_pin_b(bit)    PINB bit after the two-cycle synchroniser delay
 *
 * Marker pins are PORTB bits: the bench stamps their edges with the cycle of
 * the instruction that writes them (sbi/cbi, 2 cycles each).
 */
#ifndef PERIPH_H
#define PERIPH_H

#include <avr/io.h>

#if defined(__AVR_ATmega2560__) || defined(__AVR_ATmega1280__)
#define INT0_PIN PD0
#define INT1_PIN PD1
#else
#define INT0_PIN PD2
#define INT1_PIN PD3
#endif

/* PUD, pull-up disable: MCUCR on the 328P/2560 (§14.4.1), SFIOR on the m32. */
#if defined(MCUCR) && defined(PUD) && !defined(SFIOR)
#define PUD_REG MCUCR
#else
#define PUD_REG SFIOR
#endif

/* PINB bit `bit`, after the synchroniser delay (§14.2.4): two NOPs. Not
 * inlined, so a finding about the read names this function. */
static __attribute__((noinline, unused)) uint8_t read_pin_b(uint8_t bit)
{
    __asm__ __volatile__("nop\n\tnop");
    return (uint8_t)((PINB >> bit) & 1);
}

#if defined(__AVR_ATmega32__) || defined(__AVR_ATmega16__)
#define EXT_SENSE MCUCR
#define EXT_MASK GICR
#define EXT_FLAGS GIFR
#else
#define EXT_SENSE EICRA
#define EXT_MASK EIMSK
#define EXT_FLAGS EIFR
#endif

/* I/O addresses for inline assembly (sbi/cbi/out). */
#define IO_PORTB _SFR_IO_ADDR(PORTB)
#define IO_PINB _SFR_IO_ADDR(PINB)

// SPI pins (ATmega328P Table 14-3, ATmega2560 Table 13-6, ATmega32 PB4..PB7).
#if defined(__AVR_ATmega2560__) || defined(__AVR_ATmega1280__)
#define SPI_DDR DDRB
#define SPI_SS PB0
#define SPI_SCK PB1
#define SPI_MOSI PB2
#elif defined(__AVR_ATmega32__) || defined(__AVR_ATmega16__)
#define SPI_DDR DDRB
#define SPI_SS PB4
#define SPI_SCK PB7
#define SPI_MOSI PB5
#else
#define SPI_DDR DDRB
#define SPI_SS PB2
#define SPI_SCK PB5
#define SPI_MOSI PB3
#endif

#endif
