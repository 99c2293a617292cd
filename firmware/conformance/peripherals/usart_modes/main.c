/*
 * usart_modes - USART0 baud rate, frame format, double-buffered transmitter,
 * UDRE/TXC/RXC interrupts.
 *
 * ATmega328P §20.3.1 Table 20-1 (2560 §22.3.1, m32 "USART" Table 60): bit
 * time = 8 (UBRR + 1) cycles with U2X = 1, 16 (UBRR + 1) with U2X = 0;
 * §20.4: a frame is start + data + parity (if UPM != 0) + stop bits;
 * §20.6: "the transmit buffer" - a byte written while a frame is being
 * shifted out waits in UDR and goes out right after it (UDRE set when UDR
 * can take a new byte); TXC "is set when the entire frame in the Transmit
 * Shift Register has been shifted out and there are no new data currently
 * present in the transmit buffer"; UDRE "interrupt ... will be executed as
 * long as UDRIE is written to one"; RXC set when a frame has been received.
 *
 *  0. `ucsrb_at_reset` = UCSRnB before any write (reset value 0: receiver and
 *     transmitter off).
 *  1. 115200 U2X (UBRR = 16, 136 cycles/bit), 8N1: "ABCD" polled on UDRE,
 *     then poll TXC, marker PB0.
 *  2. Same format, "EFGH" from the UDRE interrupt; the ISR disables UDRIE
 *     after the last byte; TXC interrupt (naked, first instruction sets PB1).
 *     The main line sleeps in Idle.
 *  3. Receiver on, RXC interrupt (naked: sets PB2, reads UDR into rx[]).
 *     Marker PB3; the bench sends "xyz"; main sleeps.
 *  4. U2X = 0, UBRR = 103 (1664 cycles/bit), 8E2 (UPM = 10, USBS = 1):
 *     "IJ" polled, marker PB4 at the end.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

#if defined(__AVR_ATmega32__)
#define UDRn UDR
#define UCSRnA UCSRA
#define UCSRnB UCSRB
#define UBRRnL UBRRL
#define UBRRnH UBRRH
#define UDREn UDRE
#define TXCn TXC
#define U2Xn U2X
#define RXENn RXEN
#define TXENn TXEN
#define RXCIEn RXCIE
#define TXCIEn TXCIE
#define UDRIEn UDRIE
#define USART_UDRE_VECT USART_UDRE_vect
#define USART_TX_VECT USART_TXC_vect
#define USART_RX_VECT USART_RXC_vect
/* UCSRC shares its address with UBRRH: URSEL selects UCSRC. */
#define SET_FORMAT(v) (UCSRC = (uint8_t)((1 << URSEL) | (v)))
#define FMT_8N1 ((1 << UCSZ1) | (1 << UCSZ0))
#define FMT_8E2 ((1 << UPM1) | (1 << USBS) | (1 << UCSZ1) | (1 << UCSZ0))
#else
#define UDRn UDR0
#define UCSRnA UCSR0A
#define UCSRnB UCSR0B
#define UBRRnL UBRR0L
#define UBRRnH UBRR0H
#define UDREn UDRE0
#define TXCn TXC0
#define U2Xn U2X0
#define RXENn RXEN0
#define TXENn TXEN0
#define RXCIEn RXCIE0
#define TXCIEn TXCIE0
#define UDRIEn UDRIE0
#define USART_UDRE_VECT USART0_UDRE_vect
#define USART_TX_VECT USART0_TX_vect
#define USART_RX_VECT USART0_RX_vect
#define SET_FORMAT(v) (UCSR0C = (uint8_t)(v))
#define FMT_8N1 ((1 << UCSZ01) | (1 << UCSZ00))
#define FMT_8E2 ((1 << UPM01) | (1 << USBS0) | (1 << UCSZ01) | (1 << UCSZ00))
#endif

#if defined(__AVR_ATmega2560__)
#undef USART_UDRE_VECT
#undef USART_TX_VECT
#undef USART_RX_VECT
#define USART_UDRE_VECT USART0_UDRE_vect
#define USART_TX_VECT USART0_TX_vect
#define USART_RX_VECT USART0_RX_vect
#elif defined(__AVR_ATmega328P__)
#undef USART_UDRE_VECT
#undef USART_TX_VECT
#undef USART_RX_VECT
#define USART_UDRE_VECT USART_UDRE_vect
#define USART_TX_VECT USART_TX_vect
#define USART_RX_VECT USART_RX_vect
#endif

static const char isr_text[] = "EFGH";
volatile uint8_t isr_index;
volatile uint8_t rx[4];
volatile uint8_t rx_count;
volatile uint8_t ucsrb_at_reset = 0xFF;

static void put_polled(uint8_t c)
{
    while (!(UCSRnA & (1 << UDREn))) {
    }
    UDRn = c;
}

ISR(USART_UDRE_VECT)
{
    UDRn = (uint8_t)isr_text[isr_index++];
    if (isr_index == 4) UCSRnB &= (uint8_t) ~(1 << UDRIEn);
}

ISR(USART_TX_VECT, ISR_NAKED)
{
    asm volatile("sbi %[portb], 1\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB));
}

ISR(USART_RX_VECT)
{
    PORTB |= (1 << PB2);
    const uint8_t c = UDRn;
    if (rx_count < sizeof rx) rx[rx_count] = c;
    ++rx_count;
}

int main(void)
{
    ucsrb_at_reset = UCSRnB;
    DDRB = 0x1F;
    PORTB = 0;
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();

    /* 1 */
    UCSRnA = (1 << U2Xn);
    SET_FORMAT(FMT_8N1);
    UBRRnH = 0;
    UBRRnL = 16;
    UCSRnB = (1 << TXENn);
    put_polled('A');
    put_polled('B');
    put_polled('C');
    put_polled('D');
    UCSRnA = (1 << U2Xn) | (1 << TXCn); /* clear TXC (write one) */
    while (!(UCSRnA & (1 << TXCn))) {
    }
    PORTB |= (1 << PB0);

    /* 2 */
    UCSRnA = (1 << U2Xn) | (1 << TXCn);
    sei();
    UCSRnB = (1 << TXENn) | (1 << TXCIEn) | (1 << UDRIEn);
    while (!(PORTB & (1 << PB1))) {
        sleep_cpu();
    }

    /* 3 */
    UCSRnB = (1 << TXENn) | (1 << RXENn) | (1 << RXCIEn);
    PORTB |= (1 << PB3);
    while (rx_count < 3) {
        sleep_cpu();
    }

    /* 4 */
    cli();
    UCSRnB = 0;
    UCSRnA = 0;
    SET_FORMAT(FMT_8E2);
    UBRRnH = 0;
    UBRRnL = 103;
    UCSRnB = (1 << TXENn);
    put_polled('I');
    put_polled('J');
    while (!(UCSRnA & (1 << TXCn))) {
    }
    PORTB |= (1 << PB4);
    for (;;) {
    }
}
