#include "fw_uart.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdlib.h>

#if (FW_UART_RX_SIZE & (FW_UART_RX_SIZE - 1)) != 0 || FW_UART_RX_SIZE > 128
#error "FW_UART_RX_SIZE must be a power of two, at most 128"
#endif

#if defined(USART0_RX_vect)
#define FW_UART_RX_VECT USART0_RX_vect /* ATmega2560 */
#define FW_UART_UDRE_VECT USART0_UDRE_vect
#else
#define FW_UART_RX_VECT USART_RX_vect /* ATmega328P */
#define FW_UART_UDRE_VECT USART_UDRE_vect
#endif

#ifdef FW_UART_TX_SIZE
#if (FW_UART_TX_SIZE & (FW_UART_TX_SIZE - 1)) != 0 || FW_UART_TX_SIZE > 128
#error "FW_UART_TX_SIZE must be a power of two, at most 128"
#endif
static volatile uint8_t tx_ring[FW_UART_TX_SIZE];
static volatile uint8_t tx_head; /* written by fw_uart_putc only */
static volatile uint8_t tx_tail; /* written by the UDRE ISR only */

ISR(FW_UART_UDRE_VECT)
{
    const uint8_t tail = tx_tail;
    if (tx_head == tail) {
        UCSR0B &= (uint8_t)~(1 << UDRIE0); /* drained: no more UDRE interrupts */
        return;
    }
    UDR0 = tx_ring[tail & (FW_UART_TX_SIZE - 1)];
    tx_tail = (uint8_t)(tail + 1);
}
#endif

static volatile uint8_t rx_ring[FW_UART_RX_SIZE];
/* Free-running indices: the fill is (uint8_t)(head - tail). */
static volatile uint8_t rx_head; /* written by the ISR only */
static volatile uint8_t rx_tail; /* written by fw_uart_getc only */
volatile uint8_t fw_uart_rx_dropped;

ISR(FW_UART_RX_VECT)
{
    const uint8_t c = UDR0; /* reading UDR0 clears RXC0 */
    const uint8_t head = rx_head;
    if ((uint8_t)(head - rx_tail) >= FW_UART_RX_SIZE) {
        ++fw_uart_rx_dropped;
        return;
    }
    rx_ring[head & (FW_UART_RX_SIZE - 1)] = c;
    rx_head = (uint8_t)(head + 1);
}

void fw_uart_init(uint16_t ubrr, uint8_t u2x)
{
    UCSR0A = u2x ? (1 << U2X0) : 0;
    UCSR0C = (1 << UCSZ01) | (1 << UCSZ00); /* 8N1 */
    UBRR0H = (uint8_t)(ubrr >> 8);
    UBRR0L = (uint8_t)ubrr;
    UCSR0B = (1 << RXEN0) | (1 << TXEN0) | (1 << RXCIE0);
}

int16_t fw_uart_getc(void)
{
    const uint8_t tail = rx_tail;
    if (rx_head == tail) return -1;
    const uint8_t c = rx_ring[tail & (FW_UART_RX_SIZE - 1)];
    rx_tail = (uint8_t)(tail + 1);
    return c;
}

void fw_uart_idle(void)
{
    set_sleep_mode(SLEEP_MODE_IDLE);
    cli();
    if (rx_head == rx_tail) {
        sleep_enable();
        sei();
        sleep_cpu();
        sleep_disable();
    }
    sei();
}

void fw_uart_putc(char c)
{
#ifdef FW_UART_TX_SIZE
    const uint8_t head = tx_head;
    while ((uint8_t)(head - tx_tail) >= FW_UART_TX_SIZE) { /* full: the ISR makes room */
    }
    tx_ring[head & (FW_UART_TX_SIZE - 1)] = (uint8_t)c;
    tx_head = (uint8_t)(head + 1);
    UCSR0B |= (1 << UDRIE0);
#else
    while (!(UCSR0A & (1 << UDRE0))) { /* UDRE0: UDR0 can take a byte */
    }
    UDR0 = (uint8_t)c;
#endif
}

void fw_uart_puts(const char *s)
{
    while (*s) fw_uart_putc(*s++);
}

void fw_uart_put_i32(int32_t v)
{
    char digits[12];
    ltoa(v, digits, 10);
    fw_uart_puts(digits);
}

void fw_uart_put_u32(uint32_t v)
{
    char digits[11];
    ultoa(v, digits, 10);
    fw_uart_puts(digits);
}
