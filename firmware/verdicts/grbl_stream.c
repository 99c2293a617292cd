/*
 * grbl_stream - the part of grbl 1.1's serial protocol that decides what a
 * streamed job means for the motion judge, on the Arduino UNO + CNC shield
 * v3 (bench/boards/arduino-uno-cnc-shield-v3.yaml: X/Y STEP PD2/PD3, DIR
 * PD5/PD6 with DIR low = +, drivers enabled by PB0 low, 250 steps/mm).
 *
 * USART0 at 115200 baud (U2X0, UBRR0 = 16). As grbl's serial.c, the receive
 * interrupt takes the realtime bytes out of the stream wherever they are -
 * '!' holds the motion, '~' resumes it, '?' and every byte over 0x7F are
 * dropped - and puts the rest in a 128-byte ring (grbl's RX_BUFFER_SIZE),
 * so a host counting characters may send ahead of the answers.
 *
 * At boot it prints grbl's welcome line. One command per line, answered
 * as grbl answers it (interface.md):
 *   a line that starts with a digit    "error:1" (expected command letter)
 *   G1 ... F0                          "error:22" (undefined feed rate)
 *   G1 X<mm> Y<mm>                     "ok" when taken (as grbl's planner
 *                                      queues it), then made: a Bresenham
 *                                      line from the power-up position,
 *                                      one step event every 400 us, waiting
 *                                      while held
 *   anything else                      "ok", ignored
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define STEPS_PER_MM 250.0
#define RX_SIZE 128u

static volatile uint8_t rx_ring[RX_SIZE];
static volatile uint8_t rx_head, rx_tail;
static volatile uint8_t held;
static char line[80];

ISR(USART_RX_vect)
{
    const uint8_t b = UDR0;
    if (b == '!') {
        held = 1;
    } else if (b == '~') {
        held = 0;
    } else if (b == '?' || b > 0x7F) {
        /* grbl answers '?' with a status report; nothing here asks for one */
    } else {
        const uint8_t next = (uint8_t)((rx_head + 1u) % RX_SIZE);
        if (next != rx_tail) {
            rx_ring[rx_head] = b;
            rx_head = next;
        }
    }
}

static void put(const char *s)
{
    for (; *s; ++s) {
        loop_until_bit_is_set(UCSR0A, UDRE0);
        UDR0 = (uint8_t)*s;
    }
}

static void read_line(void)
{
    uint8_t n = 0;
    for (;;) {
        while (rx_tail == rx_head) {
        }
        const char c = (char)rx_ring[rx_tail];
        rx_tail = (uint8_t)((rx_tail + 1u) % RX_SIZE);
        if (c == '\n' || c == '\r') {
            if (n == 0) continue;
            line[n] = '\0';
            return;
        }
        if (n < sizeof line - 1) line[n++] = c;
    }
}

/* The steps of `letter`'s word, or `keep` when the line has none. */
static long target_steps(char letter, long keep)
{
    const char *p = strchr(line, letter);
    if (p == 0) return keep;
    const double mm = strtod(p + 1, 0);
    return (long)(mm * STEPS_PER_MM + (mm < 0 ? -0.5 : 0.5));
}

static void step(uint8_t bits)
{
    while (held) {
    }
    PORTD |= bits;
    _delay_us(4); /* A4988: 1 us high at least */
    PORTD &= (uint8_t)~bits;
    _delay_us(396);
}

int main(void)
{
    DDRD = _BV(PD2) | _BV(PD3) | _BV(PD5) | _BV(PD6);
    DDRB = _BV(PB0); /* PB0 low: drivers enabled */
    UCSR0A = _BV(U2X0);
    UBRR0 = 16;
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    sei();
    put("\r\nGrbl 1.1h ['$' for help]\r\n"); /* grbl's welcome (report.c), which its host waits for */
    long x = 0, y = 0;
    for (;;) {
        read_line();
        if (line[0] >= '0' && line[0] <= '9') {
            put("error:1\r\n");
            continue;
        }
        const uint8_t g1 = line[0] == 'G' && line[1] == '1' && line[2] == ' ';
        if (g1 && strstr(line, "F0") != 0) {
            put("error:22\r\n");
            continue;
        }
        put("ok\r\n");
        if (!g1) continue;
        const long tx = target_steps('X', x), ty = target_steps('Y', y);
        const long dx = tx - x, dy = ty - y;
        /* DIR low = + (the board's forward_dir); set before the first step. */
        if (dx < 0) PORTD |= _BV(PD5); else PORTD &= (uint8_t)~_BV(PD5);
        if (dy < 0) PORTD |= _BV(PD6); else PORTD &= (uint8_t)~_BV(PD6);
        _delay_us(4);
        const uint8_t xbit = _BV(PD2), ybit = _BV(PD3);
        const long ax = labs(dx), ay = labs(dy);
        const uint8_t x_major = ax >= ay;
        const long major = x_major ? ax : ay, minor = x_major ? ay : ax;
        long err = major / 2;
        for (long i = 0; i < major; ++i) {
            uint8_t bits = x_major ? xbit : ybit;
            err -= minor;
            if (err < 0) {
                err += major;
                bits |= x_major ? ybit : xbit;
            }
            step(bits);
        }
        x = tx;
        y = ty;
    }
}
