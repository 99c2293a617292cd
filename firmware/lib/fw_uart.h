/*
 * The USART0 (ATmega328P, ATmega2560) as the firmware of this repository
 * uses it: interrupt-driven receive into a ring buffer; transmit polled or
 * (with FW_UART_TX_SIZE defined, a power of two up to 128) through a ring the
 * data-register-empty interrupt drains, as the Arduino core's Serial does;
 * a few print helpers. FW_UART_RX_SIZE (a power of two, at most 128; default
 * 64) sizes the receive ring; a byte that finds it full is dropped and
 * counted. fw_uart_putc blocks only while the transmit ring is full.
 */
#ifndef FW_UART_H
#define FW_UART_H

#include <stdint.h>

#ifndef FW_UART_RX_SIZE
#define FW_UART_RX_SIZE 64
#endif

/* UBRR and U2X as the datasheet's baud tables give them (328P §20.10,
 * 2560 §22.10): 115200 baud at 16 MHz is UBRR 16 with U2X (-2.1 %). */
void fw_uart_init(uint16_t ubrr, uint8_t u2x);
/* The next received byte, or -1 when none is waiting. */
int16_t fw_uart_getc(void);
/* Sleeps (idle mode: timers and the USART run) until an interrupt, unless a
 * byte is already waiting. Race-free: SEI lets exactly the SLEEP after it
 * run before a pending interrupt is taken (328P §7.7.1), so a byte that
 * arrives between the check and the SLEEP still wakes it. */
void fw_uart_idle(void);
void fw_uart_putc(char c);
void fw_uart_puts(const char *s);
void fw_uart_put_i32(int32_t v);
void fw_uart_put_u32(uint32_t v);

extern volatile uint8_t fw_uart_rx_dropped; /* bytes lost to a full ring */

#endif
