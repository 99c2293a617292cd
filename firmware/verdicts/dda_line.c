/*
 * dda_line - straight G1 lines by Bresenham on the Arduino UNO + CNC shield
 * v3 (bench/boards/arduino-uno-cnc-shield-v3.yaml: X/Y STEP PD2/PD3, DIR
 * PD5/PD6 with DIR low = +, drivers enabled by PB0 low), at the board's 250
 * steps/mm: the step quantum every firmware's straight line has. A
 * Bresenham (DDA) line keeps the minor axis within half a step of the ideal
 * line, so the carriage is never more than one step of each axis from it.
 *
 * USART0 at 115200 baud (U2X0, UBRR0 = 16), polled. One command per line:
 *   G1 X<mm> Y<mm>   absolute, from the power-up position (0, 0); "ok" once
 *                    the move is made (one step event every 400 us)
 *   G1 ... F0        refused with grbl's "error:22" (undefined feed rate),
 *                    not moved
 *   G1 ... Q         the move, then no answer at all (a firmware that goes
 *                    silent after moving)
 *   G28 P<n>         homes X and Y to their min switches (PB1, PB2: normally
 *                    open to GND with pull-ups, low = triggered), one step
 *                    every 100 us, each axis stopping <n> steps after its
 *                    switch first reads low (a firmware that wants n + 1
 *                    readings in a row, as Marlin 1.0 wants two), and calls
 *                    where it stopped 0
 * anything else is answered "ok" and ignored.
 */
#include <avr/io.h>
#include <stdlib.h>
#include <string.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define STEPS_PER_MM 250.0

static char line[64];

static void put(char c)
{
    loop_until_bit_is_set(UCSR0A, UDRE0);
    UDR0 = (uint8_t)c;
}

static void read_line(void)
{
    uint8_t n = 0;
    for (;;) {
        loop_until_bit_is_set(UCSR0A, RXC0);
        const char c = (char)UDR0;
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
    PORTD |= bits;
    _delay_us(4); /* A4988: 1 us high at least */
    PORTD &= (uint8_t)~bits;
    _delay_us(396);
}

static void home_xy(uint8_t extra_steps)
{
    PORTD |= _BV(PD5) | _BV(PD6); /* DIR high = - */
    _delay_us(4);
    uint8_t x_after = 0, y_after = 0;
    for (;;) {
        uint8_t bits = 0;
        if (!(PINB & _BV(PB1)) && x_after <= extra_steps) ++x_after;
        if (!(PINB & _BV(PB2)) && y_after <= extra_steps) ++y_after;
        if (x_after <= extra_steps) bits |= _BV(PD2);
        if (y_after <= extra_steps) bits |= _BV(PD3);
        if (bits == 0) return;
        PORTD |= bits;
        _delay_us(4);
        PORTD &= (uint8_t)~bits;
        _delay_us(96);
    }
}

int main(void)
{
    DDRD = _BV(PD2) | _BV(PD3) | _BV(PD5) | _BV(PD6);
    DDRB = _BV(PB0); /* PB0 low: drivers enabled */
    PORTB = _BV(PB1) | _BV(PB2); /* the switches' pull-ups */
    UCSR0A = _BV(U2X0);
    UBRR0 = 16;
    UCSR0B = _BV(RXEN0) | _BV(TXEN0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    long x = 0, y = 0;
    for (;;) {
        read_line();
        if (line[0] == 'G' && line[1] == '1' && strstr(line, "F0") != 0) {
            put('e'); put('r'); put('r'); put('o'); put('r'); put(':'); put('2'); put('2'); put('\r'); put('\n');
            continue;
        }
        if (line[0] == 'G' && line[1] == '2' && line[2] == '8') {
            const char *p = strchr(line, 'P');
            home_xy(p ? (uint8_t)atoi(p + 1) : 0);
            x = 0;
            y = 0;
        }
        if (line[0] == 'G' && line[1] == '1' && line[2] == ' ') {
            const long tx = target_steps('X', x), ty = target_steps('Y', y);
            long dx = tx - x, dy = ty - y;
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
            if (strchr(line, 'Q') != 0) continue;
        }
        put('o');
        put('k');
        put('\r');
        put('\n');
    }
}
