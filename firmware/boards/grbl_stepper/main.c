/*
 * grbl_stepper - a small grbl-style step generator (ATmega328P, 16 MHz,
 * Arduino UNO + CNC shield), written for the bench: the timer patterns grbl
 * relies on, end to end.
 *
 * Pins (CNC shield v3): X/Y/Z STEP PD2/PD3/PD4, DIR PD5/PD6/PD7, stepper
 * enable PB0 (active low), limit switches PB1/PB2/PB4 (X/Y/Z, to ground,
 * internal pull-ups, pin change interrupt PCINT0). USART0 at 115200 baud, U2X
 * (UBRR0 = 16), 8N1.
 *
 * Timers, as grbl does it:
 *  - Timer1 is the step clock: CTC (WGM13:0 = 0100) at clk/1, started at boot
 *    with OCR1A still 0 and its interrupt off. A move enables OCIE1A; OCF1A is
 *    already set (it matches on every cycle while OCR1A = 0, or at the end of
 *    every period later), so the vector runs at once, and its first run writes
 *    the real period into OCR1A.
 *  - The vector first outputs the step bits computed on its previous run (a
 *    rising edge on each STEP that steps), starts Timer0 to end the pulse, then
 *    re-enables interrupts (sei: nested) and computes the next step bits
 *    (Bresenham over the three axes) plus some bookkeeping.
 *  - Timer0 at clk/8 from TCNT0 = 256 - 2 * pulse_us: its overflow vector,
 *    nested inside the step vector, clears the STEP pins and stops Timer0.
 *
 * Rates: an axis moves at most $11x mm/min; a move runs at the rate of its
 * longest axis: steps_per_s = max_rate * steps_per_mm / 60, one step event
 * every F_CPU / steps_per_s cycles (rounded down).
 * Defaults: $100/$101/$102 = 80/80/400 steps/mm, $110/$111/$112 =
 * 6000/6000/1200 mm/min (8000 steps/s, 2000 cycles per step on every axis),
 * $0 = 10 us pulse (Timer0: 20 clocks of 8 cycles = 160 cycles).
 *
 * Settings live in EEPROM (struct settings_t at address 0, version byte +
 * additive checksum); defaults are written on the first boot.
 *
 * Commands, one per line (CR, LF or CR LF; control characters dropped; an
 * empty line answered "ok" as grbl does), each answered "ok" when done:
 *   X<n> Y<n> Z<n>  relative move in steps (any subset, signed), e.g. X1600
 *   G X<mm> ...     relative move in whole millimetres (steps = mm * $10x)
 *   $<n>=<v>        set a setting ($0, $100..$102, $110..$112), saved to EEPROM
 *   $$              print the settings
 *   $X              clear an alarm
 *   ?               position in steps: <X,Y,Z>
 * A limit switch closing during a move stops it at once (the step vector is
 * disabled in the pin change vector) and prints "ALARM:1"; moves answer
 * "error:9" until $X.
 *
 * Globals for tests: `moves` (moves finished or stopped), `ocr1a_first`
 * (OCR1A as the first step vector of the last move found it), `nested_ends`
 * (pulses ended by the Timer0 vector while the step vector was running),
 * `position[3]`.
 */
#include <avr/eeprom.h>
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>
#include <stdlib.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define STEP_MASK (_BV(PD2) | _BV(PD3) | _BV(PD4))
#define DIR_MASK (_BV(PD5) | _BV(PD6) | _BV(PD7))
#define LIMIT_MASK (_BV(PB1) | _BV(PB2) | _BV(PB4))
#define ENABLE_BIT PB0

/* ---- settings in EEPROM ------------------------------------------------- */

typedef struct {
    uint8_t version;
    uint8_t pulse_us;          /* $0 */
    uint16_t steps_per_mm[3];  /* $100..$102 */
    uint16_t max_rate[3];      /* $110..$112, mm/min */
    uint8_t checksum;
} settings_t;

#define SETTINGS_VERSION 1
static settings_t settings;

static uint8_t checksum(const settings_t* s)
{
    const uint8_t* p = (const uint8_t*)s;
    uint8_t sum = 0;
    for (uint8_t i = 0; i < sizeof(settings_t) - 1; ++i) sum = (uint8_t)(sum + p[i]);
    return sum;
}

static void settings_store(void)
{
    settings.checksum = checksum(&settings);
    eeprom_update_block(&settings, (void*)0, sizeof settings);
}

static void settings_load(void)
{
    eeprom_read_block(&settings, (const void*)0, sizeof settings);
    if (settings.version == SETTINGS_VERSION && settings.checksum == checksum(&settings)) return;
    settings.version = SETTINGS_VERSION;
    settings.pulse_us = 10;
    settings.steps_per_mm[0] = 80;
    settings.steps_per_mm[1] = 80;
    settings.steps_per_mm[2] = 400;
    settings.max_rate[0] = 6000;
    settings.max_rate[1] = 6000;
    settings.max_rate[2] = 1200;
    settings_store();
}

/* ---- UART ------------------------------------------------------------------ */

static volatile uint8_t rx_buffer[64];
static volatile uint8_t rx_head, rx_tail;

ISR(USART_RX_vect)
{
    const uint8_t c = UDR0;
    const uint8_t next = (uint8_t)((rx_head + 1) & 63);
    if (next != rx_tail) {
        rx_buffer[rx_head] = c;
        rx_head = next;
    }
}

static int uart_getc(void)
{
    if (rx_head == rx_tail) return -1;
    const uint8_t c = rx_buffer[rx_tail];
    rx_tail = (uint8_t)((rx_tail + 1) & 63);
    return c;
}

static void uart_putc(char c)
{
    while (!(UCSR0A & _BV(UDRE0))) {
    }
    UDR0 = (uint8_t)c;
}

static void uart_puts(const char* s)
{
    while (*s) uart_putc(*s++);
}

static void uart_putl(int32_t v)
{
    char buf[12];
    ltoa(v, buf, 10);
    uart_puts(buf);
}

/* ---- stepper ---------------------------------------------------------------- */

typedef struct {
    uint32_t steps[3];      /* |steps| per axis */
    uint32_t counter[3];    /* Bresenham accumulators */
    uint32_t event_count;   /* steps of the longest axis */
    uint32_t events_left;
    uint16_t period;        /* cycles per step event */
    uint8_t dir_bits;       /* DIR pins for this move */
    uint8_t next_bits;      /* STEP bits for the next vector run */
    uint8_t first;          /* the next vector run is the move's first */
    uint8_t pulse_reload;   /* TCNT0 start value */
} stepper_t;

static stepper_t st;
static volatile uint8_t busy;
volatile int32_t position[3];
volatile uint8_t moves;
volatile uint16_t ocr1a_first = 0xFFFF;
volatile uint16_t nested_ends;
static volatile uint8_t running;
static volatile uint8_t alarm;
static volatile uint16_t work; /* bookkeeping of the step vector (keeps it long, like grbl's) */

static void stepper_idle(void)
{
    TIMSK1 &= (uint8_t)~_BV(OCIE1A);
    PORTB |= _BV(ENABLE_BIT);
    running = 0;
    ++moves;
}

/* Timer1 compare A: the step clock. */
ISR(TIMER1_COMPA_vect)
{
    if (busy) return;
    PORTD = (uint8_t)((PORTD & (uint8_t)~STEP_MASK) | st.next_bits); /* rising STEP edges */
    if (st.next_bits) {
        TCNT0 = st.pulse_reload;
        TCCR0B = _BV(CS01); /* clk/8: the pulse ends at the overflow */
    }
    busy = 1;
    sei(); /* the pulse end, the UART and the limit switches may interrupt from here on */

    if (st.first) {
        st.first = 0;
        ocr1a_first = OCR1A;
        OCR1A = st.period - 1; /* CTC: a match every `period` cycles from now on */
    }
    const uint8_t stepped = st.next_bits;
    for (uint8_t a = 0; a < 3; ++a) {
        if (stepped & _BV(PD2 + a)) position[a] += (st.dir_bits & _BV(PD5 + a)) ? -1 : 1;
    }
    uint8_t bits = 0;
    if (st.events_left == 0) {
        cli();
        if (running) stepper_idle();
    } else {
        --st.events_left;
        for (uint8_t a = 0; a < 3; ++a) {
            st.counter[a] += st.steps[a];
            if (st.counter[a] > st.event_count) {
                st.counter[a] -= st.event_count;
                bits |= _BV(PD2 + a);
            }
        }
        /* Bookkeeping standing for grbl's segment and planner work: a 16-bit
         * division, about 200 cycles, during which the pulse ends. The whole
         * vector stays well under the shortest step period (1000 cycles in
         * the tests) so no match is lost to the `busy` guard. */
        work = (uint16_t)(work + (uint16_t)st.events_left * 7u) / (uint16_t)(st.period | 1u);
    }
    st.next_bits = bits;
    cli();
    busy = 0;
}

/* Timer0 overflow: end of the step pulse. */
ISR(TIMER0_OVF_vect)
{
    PORTD &= (uint8_t)~STEP_MASK;
    TCCR0B = 0;
    if (busy) ++nested_ends;
}

/* Limit switches: any closed (low) stops the machine. */
ISR(PCINT0_vect)
{
    if ((PINB & LIMIT_MASK) == LIMIT_MASK) return;
    if (running) {
        TIMSK1 &= (uint8_t)~_BV(OCIE1A);
        st.events_left = 0;
        st.next_bits = 0;
        PORTB |= _BV(ENABLE_BIT);
        running = 0;
        ++moves;
    }
    alarm = 1;
}

static void stepper_init(void)
{
    DDRD |= STEP_MASK | DIR_MASK;
    DDRB |= _BV(ENABLE_BIT);
    PORTB |= _BV(ENABLE_BIT) | LIMIT_MASK; /* drivers off; pull-ups on the limits */
    PCMSK0 = _BV(PCINT1) | _BV(PCINT2) | _BV(PCINT4);
    PCICR = _BV(PCIE0);
    TIMSK0 = _BV(TOIE0);
    /* Timer1: CTC, clk/1, OCR1A = 0 (its reset value), interrupt off. */
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS10);
}

static uint32_t labs32(int32_t v) { return v < 0 ? (uint32_t)-v : (uint32_t)v; }

/* Starts a move of `steps[a]` steps per axis and waits for its end. */
static void move(const int32_t steps[3])
{
    uint32_t longest = 0;
    uint8_t axis = 0;
    for (uint8_t a = 0; a < 3; ++a) {
        st.steps[a] = labs32(steps[a]);
        if (st.steps[a] > longest) {
            longest = st.steps[a];
            axis = a;
        }
    }
    if (longest == 0) return;
    const uint32_t steps_per_s = (uint32_t)settings.max_rate[axis] * settings.steps_per_mm[axis] / 60u;
    uint32_t period = F_CPU / (steps_per_s ? steps_per_s : 1u);
    if (period > 65535u) period = 65535u;
    if (period < 200u) period = 200u;
    st.period = (uint16_t)period;
    st.event_count = longest;
    st.events_left = longest;
    for (uint8_t a = 0; a < 3; ++a) st.counter[a] = longest >> 1;
    st.dir_bits = 0;
    for (uint8_t a = 0; a < 3; ++a) {
        if (steps[a] < 0) st.dir_bits |= _BV(PD5 + a); /* as grbl: DIR high = negative */
    }
    st.next_bits = 0;
    st.first = 1;
    st.pulse_reload = (uint8_t)(256u - 2u * settings.pulse_us);
    PORTD = (uint8_t)((PORTD & (uint8_t)~DIR_MASK) | st.dir_bits);
    PORTB &= (uint8_t)~_BV(ENABLE_BIT);
    running = 1;
    TIMSK1 |= _BV(OCIE1A); /* OCF1A is set: the step vector runs at once */
    while (running) {
    }
}

/* ---- commands ----------------------------------------------------------------- */

static char line[48];

static const char* number(const char* p, int32_t* out)
{
    *out = strtol(p, (char**)&p, 10);
    return p;
}

static void print_settings(void)
{
    static const uint16_t ids[] = {100, 101, 102, 110, 111, 112};
    uart_puts("$0=");
    uart_putl(settings.pulse_us);
    uart_puts("\r\n");
    for (uint8_t i = 0; i < 6; ++i) {
        uart_putc('$');
        uart_putl(ids[i]);
        uart_putc('=');
        uart_putl(i < 3 ? settings.steps_per_mm[i] : settings.max_rate[i - 3]);
        uart_puts("\r\n");
    }
}

static uint8_t set_setting(int32_t id, int32_t value)
{
    if (value < 0 || value > 65535) return 0;
    if (id == 0 && value >= 1 && value <= 100) {
        settings.pulse_us = (uint8_t)value;
    } else if (id >= 100 && id <= 102 && value > 0) {
        settings.steps_per_mm[id - 100] = (uint16_t)value;
    } else if (id >= 110 && id <= 112 && value > 0) {
        settings.max_rate[id - 110] = (uint16_t)value;
    } else {
        return 0;
    }
    settings_store();
    return 1;
}

static void execute(void)
{
    const char* p = line;
    if (*p == 0) {
        uart_puts("ok\r\n"); /* an empty line, as grbl answers it: for syncing */
        return;
    }
    if (p[0] == '$') {
        if (p[1] == '$') {
            print_settings();
        } else if (p[1] == 'X') {
            alarm = 0;
        } else {
            int32_t id, value;
            p = number(p + 1, &id);
            if (*p != '=') {
                uart_puts("error:3\r\n");
                return;
            }
            number(p + 1, &value);
            if (!set_setting(id, value)) {
                uart_puts("error:3\r\n");
                return;
            }
        }
        uart_puts("ok\r\n");
        return;
    }
    if (p[0] == '?') {
        uart_putc('<');
        for (uint8_t a = 0; a < 3; ++a) {
            if (a) uart_putc(',');
            uart_putl(position[a]);
        }
        uart_puts(">\r\nok\r\n");
        return;
    }
    uint8_t mm = 0;
    if (p[0] == 'G') {
        mm = 1;
        ++p;
    }
    int32_t steps[3] = {0, 0, 0};
    while (*p) {
        if (*p == ' ') {
            ++p;
            continue;
        }
        const char c = *p;
        if (c != 'X' && c != 'Y' && c != 'Z') {
            uart_puts("error:2\r\n");
            return;
        }
        const uint8_t a = (uint8_t)(c == 'X' ? 0 : c == 'Y' ? 1 : 2);
        int32_t v;
        p = number(p + 1, &v);
        steps[a] = mm ? v * (int32_t)settings.steps_per_mm[a] : v;
    }
    if (alarm) {
        uart_puts("error:9\r\n");
        return;
    }
    move(steps);
    if (alarm) {
        uart_puts("ALARM:1\r\n");
        return;
    }
    uart_puts("ok\r\n");
}

int main(void)
{
    settings_load();
    UCSR0A = _BV(U2X0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    UBRR0 = 16; /* 16e6 / (8 * 17) = 117647 baud, 115200 - 2.1 % */
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
    stepper_init();
    sei();
    uart_puts("avrbench grbl_stepper ['$' for help]\r\n");

    uint8_t n = 0;
    uint8_t after_cr = 0;
    for (;;) {
        const int c = uart_getc();
        if (c < 0) continue;
        if (c == '\r' || c == '\n') {
            /* A line ends at CR, LF or CR LF: the LF of a CR LF ends none. */
            if (c == '\r' || !after_cr) {
                line[n] = 0;
                execute();
                n = 0;
            }
            after_cr = c == '\r';
        } else {
            after_cr = 0;
            /* Control characters are dropped, as grbl's protocol.c drops
             * them: a NUL once ended the line early, unanswered. */
            if (c >= ' ' && n < sizeof line - 1) line[n++] = (char)c;
        }
    }
}
