/*
 * data_init - initialised data must reach RAM from its load address.
 *
 * avr-libc's start-up (__do_copy_data) copies .data from flash, starting at
 * its load address __data_load_start, to RAM. This firmware has a string and
 * a table in .data, sends the string on USART0 (115200 baud with U2X0, 8N1:
 * UBRR0 = 16, as firmware/uart_echo), stores the sum of the table in
 * `table_sum` and then sleeps (idle, interrupts off is avoided: SLEEP with
 * SE = 0 is a NOP, so it loops on SLEEP).
 *
 * Expected, from the source: the bytes "ok\n", and table_sum = 1 + 2 + 4 +
 * 8 + 16 + 32 + 64 + 128 = 255 + 0x1000 = 0x10ff (the last entry is 0x1000).
 * Built twice: with .mmcu moved out of the flash window, and with .mmcu where
 * the linker places it by default (between .text and .data).
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

static char message[] = "ok\n";
static volatile uint16_t table[] = {1, 2, 4, 8, 16, 32, 64, 128, 0x1000};
volatile uint16_t table_sum;

int main(void) {
    UCSR0A = _BV(U2X0);
    UBRR0 = 16;
    UCSR0B = _BV(TXEN0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    for (const char* p = message; *p != '\0'; ++p) {
        loop_until_bit_is_set(UCSR0A, UDRE0);
        UDR0 = (uint8_t)*p;
    }
    uint16_t sum = 0;
    for (uint8_t i = 0; i < sizeof table / sizeof table[0]; ++i) sum += table[i];
    table_sum = sum;
    for (;;) {
    }
}
