/*
 * uart_echo - USART0 at 115200 baud (nominal), 8N1, polled.
 *
 * Sends the banner "avrbench uart_echo\r\n" once, back to back, then echoes
 * every received byte. PB5 (UNO D13) is high from the moment a byte has been
 * received until its echo has been handed to the transmitter.
 *
 * Baud rate (USART0, "Asynchronous Double Speed Mode (U2Xn)"):
 *   BAUD = f_osc / (8 * (UBRR0 + 1)) with U2X0 = 1
 *   UBRR0 = 16e6 / (8 * 115200) - 1 = 16.36 -> 16
 *   BAUD  = 16e6 / (8 * 17) = 117647 bit/s (+2.1 %, as in the datasheet's
 *           baud-rate table for 16 MHz, U2X = 1)
 *   one bit = 8 * 17 = 136 CPU cycles; one 8N1 frame (start + 8 data + stop
 *           = 10 bits) = 1360 CPU cycles = 85 us.
 * Back-to-back transmission (UDRE0 polled, transmit buffer refilled as soon
 * as it is empty) therefore puts one frame on TXD every 1360 cycles.
 */
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define UBRR_VALUE 16 /* see header: 16e6 / (8 * 115200) - 1, rounded down */

static const char banner[] PROGMEM = "avrbench uart_echo\r\n";

static void uart_putc(uint8_t c)
{
    /* UDRE0 = 1: the transmit buffer (UDR0) can take a new byte. */
    while (!(UCSR0A & _BV(UDRE0))) {
    }
    UDR0 = c;
}

int main(void)
{
    DDRB = _BV(PB5);

    /* Frame format and speed first, enables last. The datasheet allows any
     * order while the USART is disabled, but simavr 1.6 computes its byte
     * time only when UBRR0L is written, from the U2X0 and UCSZ0 bits as they
     * are at that moment; this order gives the same result on both. */

#ifndef UART_SPEED_LAST
    /* U2X0 = 1: double speed, 8 samples per bit (see header). Writing the
     * other bits 0 keeps MPCM0 off and TXC0 untouched (it is cleared by
     * writing a one, not a zero). */
    UCSR0A = _BV(U2X0);

    /* UMSEL01:0 = 00 asynchronous, UPM01:0 = 00 no parity, USBS0 = 0 one stop
     * bit, UCSZ01:0 = 11 (with UCSZ02 = 0 in UCSR0B) 8 data bits -> 8N1. */
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);

    /* UBRR0 is 12 bits; the 16-bit store writes UBRR0H then UBRR0L, and the
     * prescaler is updated on the UBRR0L write. */
    UBRR0 = UBRR_VALUE;
#else
    /* The uart_echo_speed_last variant: the same settings in the opposite
     * order, UBRR0 first, then U2X0 and the frame format. The datasheet
     * (§19.10) makes the order irrelevant while the USART is disabled;
     * simavr 1.6 recomputes its byte time on UBRR0L writes only and would
     * keep the single-speed byte time here. */
    UBRR0 = UBRR_VALUE;
    UCSR0A = _BV(U2X0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
#endif

    /* Receiver and transmitter on, no interrupts (polled). */
    UCSR0B = _BV(RXEN0) | _BV(TXEN0);

    for (const char *p = banner; pgm_read_byte(p) != '\0'; ++p) {
        uart_putc(pgm_read_byte(p));
    }

    for (;;) {
        /* RXC0 = 1: an unread byte is in the receive buffer. */
        while (!(UCSR0A & _BV(RXC0))) {
        }
        uint8_t c = UDR0; /* reading UDR0 clears RXC0 */
        PORTB |= _BV(PB5);
        uart_putc(c);
        PORTB &= (uint8_t)~_BV(PB5);
    }
}
