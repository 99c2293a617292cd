/*
 * arduino_runtime.h - the parts of the Arduino 1.6 core (wiring.c,
 * HardwareSerial, Print) that seed 003's sketches rely on, in C:
 *   - Timer0 fast PWM, clk/64, overflow ISR counting millis/micros (1024 us
 *     per overflow); micros(); delay(), which busy-waits on micros() in
 *     1000 us steps (wiring.c of Arduino 1.6);
 *   - Serial at 9600 baud (U2X, UBRR0 = 207) with a receive interrupt into a
 *     64-byte ring buffer and blocking transmit; print() of strings, integers
 *     and floats (2 decimals, Print::printFloat).
 * arduino_init() is Arduino's init(): Timer0 and interrupts on.
 */
#ifndef ARDUINO_RUNTIME_H
#define ARDUINO_RUNTIME_H

#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

volatile unsigned long timer0_overflow_count;
volatile unsigned long timer0_millis;
static unsigned char timer0_fract;

ISR(TIMER0_OVF_vect)
{
    unsigned long m = timer0_millis;
    unsigned char f = timer0_fract;
    m += 1;  /* MILLIS_INC: 1024 us per overflow */
    f += 3;  /* FRACT_INC = (1024 % 1000) >> 3 */
    if (f >= 125) { /* FRACT_MAX = 1000 >> 3 */
        f -= 125;
        m += 1;
    }
    timer0_fract = f;
    timer0_millis = m;
    timer0_overflow_count++;
}

/* millis(): timer0_millis read with interrupts off (Arduino's wiring.c) */
static inline unsigned long __attribute__((unused)) millis(void)
{
    const uint8_t old_sreg = SREG;
    cli();
    const unsigned long m = timer0_millis;
    SREG = old_sreg;
    return m;
}

static inline unsigned long micros(void)
{
    unsigned long m;
    uint8_t old_sreg = SREG, t;
    cli();
    m = timer0_overflow_count;
    t = TCNT0;
    if ((TIFR0 & _BV(TOV0)) && (t < 255)) m++;
    SREG = old_sreg;
    return ((m << 8) + t) * (64 / (F_CPU / 1000000L));
}

static inline void delay(unsigned long ms)
{
    uint16_t start = (uint16_t)micros();
    while (ms > 0) {
        if (((uint16_t)micros() - start) >= 1000) {
            ms--;
            start += 1000;
        }
    }
}

#define RX_BUFFER_SIZE 64
static volatile uint8_t rx_buffer[RX_BUFFER_SIZE];
static volatile uint8_t rx_head, rx_tail;

ISR(USART_RX_vect)
{
    uint8_t c = UDR0;
    uint8_t next = (uint8_t)((rx_head + 1) % RX_BUFFER_SIZE);
    if (next != rx_tail) {
        rx_buffer[rx_head] = c;
        rx_head = next;
    }
}

static inline void serial_begin(void)
{
    /* HardwareSerial::begin(9600) at 16 MHz: U2X, UBRR = (F_CPU/4/9600 - 1)/2
     * = 207. The frame format is written before UBRR (simavr takes the byte
     * time from the settings at the UBRR write). */
    UCSR0A = _BV(U2X0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    UBRR0H = 0;
    UBRR0L = 207;
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
}

static inline uint8_t serial_available(void) { return rx_head != rx_tail; }

static inline uint8_t serial_read(void)
{
    uint8_t c = rx_buffer[rx_tail];
    rx_tail = (uint8_t)((rx_tail + 1) % RX_BUFFER_SIZE);
    return c;
}

static inline void serial_write(char c)
{
    while (!(UCSR0A & _BV(UDRE0))) {
    }
    UDR0 = (uint8_t)c;
}

static inline void print_str(const char *s)
{
    while (*s) serial_write(*s++);
}

static inline void println(void) { print_str("\r\n"); }

static inline void print_ulong(unsigned long n)
{
    char buf[11];
    uint8_t i = 0;
    do {
        buf[i++] = (char)('0' + n % 10);
        n /= 10;
    } while (n);
    while (i) serial_write(buf[--i]);
}

static inline void print_long(long n)
{
    if (n < 0) {
        serial_write('-');
        print_ulong((unsigned long)-n);
    } else {
        print_ulong((unsigned long)n);
    }
}

/* Print::printFloat(number, 2) */
static inline void print_float(double number)
{
    unsigned long int_part;
    double remainder;
    uint8_t digits = 2;
    if (number < 0.0) {
        serial_write('-');
        number = -number;
    }
    number += 0.005;
    int_part = (unsigned long)number;
    remainder = number - (double)int_part;
    print_ulong(int_part);
    serial_write('.');
    while (digits-- > 0) {
        unsigned int to_print;
        remainder *= 10.0;
        to_print = (unsigned int)remainder;
        serial_write((char)('0' + to_print));
        remainder -= to_print;
    }
}

static inline void arduino_init(void)
{
    TCCR0A = _BV(WGM01) | _BV(WGM00);
    TCCR0B = _BV(CS01) | _BV(CS00);
    TIMSK0 = _BV(TOIE0);
    sei();
}

#endif /* ARDUINO_RUNTIME_H */
