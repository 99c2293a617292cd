/*
 * stepdir_test - a line-command step/dir firmware for the Arduino UNO + CNC
 * shield v3 (grbl's default pin map), with exactly known pulse timing, so the
 * bench's UART host and step/dir models can be checked against numbers.
 *
 * Pins (grbl 1.1 cpu_map.h, CPU_MAP_ATMEGA328P):
 *   STEP X/Y/Z = PD2/PD3/PD4, DIR X/Y/Z = PD5/PD6/PD7 (high = positive moves)
 *   stepper enable = PB0, active low (drivers disabled after reset, E1 enables)
 *   limits X/Y/Z = PB1/PB2/PB4, inputs with internal pull-ups (not used yet)
 * USART0: 115200 baud nominal, U2X0 = 1, UBRR0 = 16 (117647 baud, 1360
 * cycles per 8N1 frame), interrupt-driven receive into a 128-byte ring buffer
 * like grbl's serial.c; polled transmit. The main loop sleeps (idle) while
 * the ring buffer is empty.
 *
 * Lines end in '\n' (or '\r'); empty lines get no answer. Each command is
 * executed, then answered "ok\n"; problems are answered "error:N\n" instead
 * (numbers as grbl 1.1 uses them where one fits):
 *   error:1  unknown command letter
 *   error:2  missing or malformed number
 *   error:3  number out of range
 *   error:11 line longer than 80 characters (grbl: max characters per line)
 * Commands (one per line, letter then a decimal number, no spaces):
 *   X<n> Y<n> Z<n>  move that axis n steps, |n| <= 65535; n > 0 sets DIR high
 *   W<us>   STEP high time, 1..100 us (default 5)
 *   L<us>   STEP low time, 1..65535 us (default 45): period = W + L
 *   S<us>   DIR-to-STEP setup time, 0..65535 us (default 5); 0 writes DIR
 *           and the first STEP rising edge in the same instruction
 *   E1/E0   enable/disable the drivers (PB0 low/high)
 *   ?       report "X:<n> Y:<n> Z:<n>" (positions in steps), then ok
 *   T       never answered (the firmware goes on with the next line)
 *   Q       stop answering anything, for good
 *   A<n>    answer "ALARM:<n>" instead of ok (a grbl-style alarm)
 *   K       answer "!! killed" instead of ok (a Teacup/Marlin-style kill)
 *   M<text> print "[MSG:<text>]" then ok (an informational line)
 * Exact pulse timing: see run_steps() and README.md.
 *
 * Globals for tests: rx_overflow (1 once a received byte found the ring
 * buffer full), rx_max_fill (most bytes ever waiting in it), rx_bytes and
 * lines_received (bytes and non-empty lines received), position[3].
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <stdlib.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define UBRR_VALUE 16 /* 16e6 / (8 * 115200) - 1 = 16.36 -> 16 (U2X0 = 1) */

/* --- receive ring buffer (grbl serial.c style) ---------------------------- */

#define RX_BUFFER_SIZE 128 /* a power of two; grbl 1.1's RX_BUFFER_SIZE */
#define LINE_BUFFER_SIZE 80 /* grbl 1.1's LINE_BUFFER_SIZE */

static volatile uint8_t rx_buffer[RX_BUFFER_SIZE];
/* Free-running 8-bit indices: the fill is (uint8_t)(head - tail), 0..128, so
 * all 128 bytes are usable (grbl's head/tail scheme keeps one slot free). */
static volatile uint8_t rx_head; /* written by the ISR only */
static volatile uint8_t rx_tail; /* written by the main loop only */

volatile uint8_t rx_overflow;
volatile uint8_t rx_max_fill;
volatile uint16_t rx_bytes;
volatile uint16_t lines_received;
volatile int32_t position[3];

ISR(USART_RX_vect)
{
    const uint8_t c = UDR0; /* reading UDR0 clears RXC0 */
    const uint8_t head = rx_head;
    const uint8_t fill = (uint8_t)(head - rx_tail);
    ++rx_bytes;
    if (fill >= RX_BUFFER_SIZE) {
        rx_overflow = 1; /* byte lost, as grbl would lose it */
        return;
    }
    rx_buffer[head & (RX_BUFFER_SIZE - 1)] = c;
    rx_head = (uint8_t)(head + 1);
    if (fill + 1 > rx_max_fill) rx_max_fill = (uint8_t)(fill + 1);
}

static uint8_t rx_getc(void)
{
    /* Sleep (idle) until the ISR has put a byte in; cli ... sei; sleep is the
     * race-free pattern: SEI lets exactly one more instruction (SLEEP) run
     * before a pending interrupt is taken, and that interrupt wakes it. */
    cli();
    while (rx_head == rx_tail) {
        sleep_enable();
        sei();
        sleep_cpu();
        sleep_disable();
        cli();
    }
    sei();
    const uint8_t tail = rx_tail;
    const uint8_t c = rx_buffer[tail & (RX_BUFFER_SIZE - 1)];
    rx_tail = (uint8_t)(tail + 1);
    return c;
}

/* --- polled transmit ---------------------------------------------------------- */

static void tx_putc(char c)
{
    while (!(UCSR0A & _BV(UDRE0))) { /* UDRE0 = 1: UDR0 can take a byte */
    }
    UDR0 = (uint8_t)c;
}

static void tx_puts(const char *s)
{
    while (*s != '\0') tx_putc(*s++);
}

static void tx_long(int32_t v)
{
    char digits[12];
    ltoa(v, digits, 10);
    tx_puts(digits);
}

/* --- step generation ------------------------------------------------------- */

static uint8_t step_high_us = 5;   /* W */
static uint16_t step_low_us = 45;  /* L */
static uint16_t dir_setup_us = 5;  /* S */

/*
 * Emits `count` (>= 1) STEP pulses with exact cycle timing (16 cycles = 1 us
 * at 16 MHz). `lo` is PORTD with the new DIR bits and STEP low, `hi` the same
 * with the STEP bit set. Every pin change is one OUT (1 cycle); a pin changes
 * at the end of the OUT, so the time between two edges is the sum of the
 * instruction cycles from one OUT to the next (AVR Instruction Set Manual:
 * OUT, NOP, MOV, DEC, CLI, SEI, MOVW 1 cycle; RJMP, SBIW 2; BRNE 2 taken,
 * 1 not taken; CP/CPC 1, BREQ 2/1).
 *
 * D(n), the delay loop "rjmp 5f; 4: nop x10; 5: nop x2; sbiw; brne 4b",
 * takes 2 + (2 + 2 + 2) + 16 (n - 2) + 15 = 16 n - 9 cycles for n >= 2 and
 * 2 + 2 + 2 + 1 = 7 = 16 - 9 for n = 1.
 * The high loop "3: nop x13; dec; brne 3b" takes 16 W - 1 cycles.
 *
 *   DIR setup (S >= 1): out lo | movw | nop x5 | D(S) | mov | cli | out hi
 *                       1 + 1 + 5 + (16 S - 9) + 1 + 1 = 16 S cycles
 *   DIR setup (S = 0):  the first "out hi" changes DIR and STEP together
 *   STEP high:          out hi | high loop | out lo = 1 + (16 W - 1) = 16 W
 *   STEP low:           out lo | sei | movw | D(L) | sbiw | brne | mov | cli
 *                       | out hi = 1 + 1 + 1 + (16 L - 9) + 2 + 2 + 1 + 1 = 16 L
 * The last pulse is followed by the same 16 L low cycles before returning.
 * Interrupts are off during each high phase only (W <= 100 us, less than the
 * two 85 us frames the USART buffers); a receive interrupt taken in a low
 * phase lengthens that low phase by the ISR's cycles.
 */
static void run_steps(uint8_t hi, uint8_t lo, uint16_t count)
{
    uint16_t n = count;
    uint16_t tmp;
    uint8_t t8;
    __asm__ __volatile__(
        "cp   %A[s], __zero_reg__\n\t"
        "cpc  %B[s], __zero_reg__\n\t"
        "breq 1f\n\t"
        "out  %[port], %[lo]\n\t" /* DIR edge */
        "movw %[tmp], %[s]\n\t"
        "nop\n\tnop\n\tnop\n\tnop\n\tnop\n\t"
        "rjmp 6f\n\t"
        "7:\n\t"
        ".rept 10\n\tnop\n\t.endr\n\t"
        "6:\n\t"
        "nop\n\tnop\n\t"
        "sbiw %[tmp], 1\n\t"
        "brne 7b\n\t"
        "1:\n\t"
        "mov  %[t8], %[w]\n\t"
        "cli\n\t"
        "out  %[port], %[hi]\n\t" /* STEP rising edge */
        "3:\n\t"
        ".rept 13\n\tnop\n\t.endr\n\t"
        "dec  %[t8]\n\t"
        "brne 3b\n\t"
        "out  %[port], %[lo]\n\t" /* STEP falling edge */
        "sei\n\t"
        "movw %[tmp], %[l]\n\t"
        "rjmp 5f\n\t"
        "4:\n\t"
        ".rept 10\n\tnop\n\t.endr\n\t"
        "5:\n\t"
        "nop\n\tnop\n\t"
        "sbiw %[tmp], 1\n\t"
        "brne 4b\n\t"
        "sbiw %[n], 1\n\t"
        "brne 1b\n\t"
        : [n] "+w"(n), [tmp] "=&w"(tmp), [t8] "=&r"(t8)
        : [port] "I"(_SFR_IO_ADDR(PORTD)), [hi] "r"(hi), [lo] "r"(lo), [w] "r"(step_high_us),
          [l] "r"(step_low_us), [s] "r"(dir_setup_us)
        : "memory");
}

static void move_axis(uint8_t axis, int32_t steps)
{
    if (steps == 0) return;
    const uint8_t step_bit = (uint8_t)_BV(PD2 + axis);
    const uint8_t dir_bit = (uint8_t)_BV(PD5 + axis);
    uint8_t lo = (uint8_t)(PORTD & (uint8_t)~step_bit);
    uint16_t count;
    if (steps > 0) {
        lo |= dir_bit;
        count = (uint16_t)steps;
    } else {
        lo &= (uint8_t)~dir_bit;
        count = (uint16_t)(-steps);
    }
    run_steps((uint8_t)(lo | step_bit), lo, count);
    position[axis] += steps;
}

/* --- command interpreter ---------------------------------------------------- */

static uint8_t muted; /* Q: never answer again */

/* Parses an optional sign and at least one digit up to the end of the string.
 * Returns 0 and sets *out, or 2 (grbl error:2, bad number format). */
static uint8_t parse_number(const char *s, int32_t *out)
{
    uint8_t negative = 0;
    if (*s == '-' || *s == '+') negative = (*s++ == '-');
    if (*s == '\0') return 2;
    int32_t v = 0;
    while (*s != '\0') {
        if (*s < '0' || *s > '9') return 2;
        if (v > 100000000L) return 3; /* far out of every range; stops overflow */
        v = v * 10 + (*s++ - '0');
    }
    *out = negative ? -v : v;
    return 0;
}

/* Executes one line; returns 0 for "ok", an error number, or 0xFF for "no
 * answer" (T, Q, A, K print their own answers or none). */
static uint8_t execute(char *line)
{
    const char letter = line[0];
    int32_t value = 0;
    uint8_t err;
    switch (letter) {
    case 'X':
    case 'Y':
    case 'Z':
        if ((err = parse_number(line + 1, &value)) != 0) return err;
        if (value > 65535L || value < -65535L) return 3;
        move_axis((uint8_t)(letter - 'X'), value);
        return 0;
    case 'W':
        if ((err = parse_number(line + 1, &value)) != 0) return err;
        if (value < 1 || value > 100) return 3;
        step_high_us = (uint8_t)value;
        return 0;
    case 'L':
        if ((err = parse_number(line + 1, &value)) != 0) return err;
        if (value < 1 || value > 65535L) return 3;
        step_low_us = (uint16_t)value;
        return 0;
    case 'S':
        if ((err = parse_number(line + 1, &value)) != 0) return err;
        if (value < 0 || value > 65535L) return 3;
        dir_setup_us = (uint16_t)value;
        return 0;
    case 'E':
        if ((err = parse_number(line + 1, &value)) != 0) return err;
        if (value == 1) {
            PORTB &= (uint8_t)~_BV(PB0); /* active low: enabled */
        } else if (value == 0) {
            PORTB |= _BV(PB0);
        } else {
            return 3;
        }
        return 0;
    case '?':
        if (line[1] != '\0') return 2;
        tx_puts("X:");
        tx_long(position[0]);
        tx_puts(" Y:");
        tx_long(position[1]);
        tx_puts(" Z:");
        tx_long(position[2]);
        tx_putc('\n');
        return 0;
    case 'T':
        return 0xFF;
    case 'Q':
        muted = 1;
        return 0xFF;
    case 'A':
        if ((err = parse_number(line + 1, &value)) != 0) return err;
        tx_puts("ALARM:");
        tx_long(value);
        tx_putc('\n');
        return 0xFF;
    case 'K':
        tx_puts("!! killed\n");
        return 0xFF;
    case 'M':
        tx_puts("[MSG:");
        tx_puts(line + 1);
        tx_puts("]\n");
        return 0;
    default:
        return 1;
    }
}

static void answer(uint8_t result)
{
    if (muted || result == 0xFF) return;
    if (result == 0) {
        tx_puts("ok\n");
    } else {
        tx_puts("error:");
        tx_long(result);
        tx_putc('\n');
    }
}

int main(void)
{
    DDRD = _BV(PD2) | _BV(PD3) | _BV(PD4) | _BV(PD5) | _BV(PD6) | _BV(PD7);
    PORTD = 0;
    DDRB = _BV(PB0);                               /* enable output, limits inputs */
    PORTB = _BV(PB0) | _BV(PB1) | _BV(PB2) | _BV(PB4); /* disabled; limit pull-ups on */

    /* Speed and frame format before the enables (see uart_echo). */
    UCSR0A = _BV(U2X0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00); /* 8N1 */
    UBRR0 = UBRR_VALUE;
    UCSR0B = _BV(RXCIE0) | _BV(RXEN0) | _BV(TXEN0);

    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();

    tx_puts("stepdir_test ready\r\n"); /* grbl-style banner, \r\n like grbl's */

    char line[LINE_BUFFER_SIZE + 1];
    uint8_t length = 0;
    uint8_t too_long = 0;
    for (;;) {
        const char c = (char)rx_getc();
        if (c == '\n' || c == '\r') {
            if (length == 0 && !too_long) continue; /* empty line: no answer */
            ++lines_received;
            line[length] = '\0';
            answer(too_long ? 11 : (muted ? 0xFF : execute(line)));
            length = 0;
            too_long = 0;
        } else if (length < LINE_BUFFER_SIZE) {
            line[length++] = c;
        } else {
            too_long = 1;
        }
    }
}
