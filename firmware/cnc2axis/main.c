/*
 * cnc2axis - seed 002's two-axis pen plotter (Iakovou 2021) on an Arduino UNO
 * (ATmega328P, 16 MHz) with two DRV8825s at 1/32 (bench/boards/
 * cnc2axis-seed002.yaml). The PC does the maths; the MCU turns binary
 * records into step trains, as the thesis' assembly firmware does.
 *
 * Pins (digest §1): PORTB is the "START byte": PB0 X DIR (0 = +X), PB2 X EN
 * and PB4 Y EN (1 = disabled), PB5 Y DIR (0 = +Y); PD6 = OC0A is X STEP
 * (Timer0 CTC toggle), PB3 = OC2A is Y STEP (Timer2 CTC toggle); PB1 = OC1A
 * the pen servo; PC0/1/2 X M0/M1/M2 and PC5/4/3 Y M0/M1/M2 (reversed);
 * PD2 / PD3 the X / Y origin switches, 1 at the origin.
 *
 * Steps: both timers at clk/1024 toggle their STEP pin on every compare
 * match, so a step (one rising edge) takes two matches: f_STEP = 16 MHz /
 * (2 * 1024 * (OCR + 1)); the firmware counts every second match.
 *
 * Serial: 9600 8N1 (UBRR0 = 103), stop-and-wait: one ACK (0x06) per command
 * or arc record, NAK (0x15) for an unknown command byte. Records (counts
 * little-endian; COUNT is 2 bytes, 3 in the IMPROVED build):
 *   0x00 G00  COUNT stepx, COUNT stepy, OCR0A, OCR2A, START   both axes counted
 *                                          (X by the Timer0 interrupt, Y polled), pen up
 *   0x01 G01  COUNT stepx, [IMPROVED: COUNT stepy,] OCR0A, OCR2A, START   pen down;
 *             X counted by polling OCF0A; Y runs open loop until X is done
 *             (IMPROVED: Y counted by the Timer2 interrupt)
 *   0x02 / 0x03 G02 / G03: then arc records DX, [IMPROVED: DY,] V_X (OCR0A),
 *             V_Y (OCR2A), DIR (START), one per chord; while one chord runs
 *             the next is received; the Timer0 interrupt counts DX X steps
 *             and then stops counting (the motors keep turning until the next
 *             chord loads; IMPROVED: X and Y both counted, each switched off
 *             at its count); a record with both EN bits set ends the arc.
 *             ACK when a record is loaded.
 *   0x3B M30  pen up, both drivers off, ACK, sleep with interrupts off.
 * After every G00/G01 both EN bits are 1.
 *
 * Power-up: homing, both axes toward the origin (DIR = 1) at OCR 3
 * (12.2 mm/s at 1/32); each axis' driver is switched off as soon as its
 * switch reads 1, and the switch is re-read after 2 ms (software debounce)
 * before the axis counts as home. (The thesis re-reads first and switches
 * off after: the steps of that delay run past the origin.)
 *
 * Pen servo: Timer1 phase-correct PWM, mode 10, ICR1 = 19999 at clk/8:
 * 50.0025 Hz; OCR1A 1499 (1.499 ms, 0 deg) pen up, 2000 (2.0 ms, +90 deg)
 * pen down (the thesis' formula f/(2N(1+TOP)) is mode 10's; digest §1).
 *
 * The thesis-faithful build (default) keeps 16-bit step counters (a move of
 * more than 65535 microsteps, 409.6 mm at 1/32, wraps) and Y open loop in
 * G01 and arcs; IMPROVED has 24-bit counters, counts Y everywhere and lets
 * the pen settle (200 ms) before moving after it goes up or down.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#ifdef IMPROVED
typedef uint32_t count_t;
#define COUNT_BYTES 3
#else
typedef uint16_t count_t;
#define COUNT_BYTES 2
#endif

#define ACK 0x06
#define NAK 0x15

#define X_DIR PB0
#define X_EN PB2
#define Y_EN PB4
#define Y_DIR PB5
#define START_MASK (_BV(X_DIR) | _BV(X_EN) | _BV(Y_EN) | _BV(Y_DIR))
#define PEN_UP_OCR 1499
#define PEN_DOWN_OCR 2000
#define HOMING_OCR 3

volatile count_t x_left;     /* X steps still to count (Timer0 interrupt) */
static volatile uint8_t x_half;
static volatile uint8_t x_end_disables; /* G00: switch X off at the count's end */
#ifdef IMPROVED
volatile count_t y_left;
static volatile uint8_t y_half;
#endif
volatile uint16_t acks;      /* for tests: ACKs sent */

/* Waits, asleep (idle: the timers run), until an interrupt has counted
 * `*left` down to 0. The count is read with interrupts off: read byte by byte
 * while an interrupt decrements it, 0x0100 -> 0x00FF can read as 0x0000 and
 * end a move early. SEI lets exactly the SLEEP after it run before a pending
 * interrupt is taken (328P §7.7), so the last decrement cannot slip between
 * the check and the SLEEP. */
static void wait_zero(volatile count_t *left)
{
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) {
        cli();
        if (*left == 0) {
            sei();
            return;
        }
        sleep_enable();
        sei();
        sleep_cpu();
        sleep_disable();
    }
}
volatile uint8_t homed;

/* --- USART0, polled (the assembly firmware has no receive interrupt) ------ */
static void uart_init(void)
{
    UBRR0H = 0;
    UBRR0L = 103; /* 9600 baud at 16 MHz (328P Table 20-7: 0.2 % error) */
    UCSR0A = 0;
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    UCSR0B = _BV(RXEN0) | _BV(TXEN0);
}

static uint8_t rx(void)
{
    while (!(UCSR0A & _BV(RXC0))) {
    }
    return UDR0;
}

static void tx(uint8_t c)
{
    while (!(UCSR0A & _BV(UDRE0))) {
    }
    UDR0 = c;
    if (c == ACK) ++acks;
}

static count_t rx_count(void)
{
    count_t v = 0;
    for (uint8_t i = 0; i < COUNT_BYTES; ++i) v |= (count_t)rx() << (8 * i);
    return v;
}

/* --- step timers ------------------------------------------------------------ */
static void timers_run(void)
{
    TCCR0B = _BV(CS02) | _BV(CS00);            /* clk/1024 */
    TCCR2B = _BV(CS22) | _BV(CS21) | _BV(CS20); /* clk/1024 */
}

static void apply_start(uint8_t start) { PORTB = (uint8_t)((PORTB & (uint8_t)~START_MASK) | (start & START_MASK)); }

ISR(TIMER0_COMPA_vect)
{
    if (!x_half) {
        x_half = 1;
        return;
    }
    x_half = 0;
    if (x_left != 0 && --x_left == 0) {
        TIMSK0 = 0;
        if (x_end_disables) PORTB |= _BV(X_EN);
    }
}

#ifdef IMPROVED
ISR(TIMER2_COMPA_vect)
{
    if (!y_half) {
        y_half = 1;
        return;
    }
    y_half = 0;
    if (y_left != 0 && --y_left == 0) {
        TIMSK2 = 0;
        PORTB |= _BV(Y_EN);
    }
}
#endif

/* Waits for `count` pairs of Timer2 matches (OCF2A polled, cleared by writing 1). */
static void count_y_polled(count_t count)
{
    uint8_t half = 0;
    while (count != 0) {
        while (!(TIFR2 & _BV(OCF2A))) {
        }
        TIFR2 = _BV(OCF2A);
        if (half) --count;
        half ^= 1;
    }
}

/* The thesis' Count_Steps: X counted by polling OCF0A. */
static void count_x_polled(count_t count)
{
    uint8_t half = 0;
    while (count != 0) {
        while (!(TIFR0 & _BV(OCF0A))) {
        }
        TIFR0 = _BV(OCF0A);
        if (half) --count;
        half ^= 1;
    }
}

/* --- pen servo (Timer1) -------------------------------------------------------- */
static void pen(uint16_t ocr)
{
    if (OCR1A == ocr) return;
    OCR1A = ocr;
#ifdef IMPROVED
    /* Let the pen land or lift before the carriage moves: an SG90 turns 90
     * deg in 0.15 s (0.1 s / 60 deg at 4.8 V), and the new width starts at
     * the next 20 ms frame. The thesis moves at once, so the pen touches down
     * late on a line's start and drags into the next rapid. */
    _delay_ms(200);
#endif
}

static void pen_init(void)
{
    DDRB |= _BV(PB1);
    ICR1 = 19999;
    OCR1A = PEN_UP_OCR;
    TCCR1A = _BV(COM1A1) | _BV(WGM11);           /* mode 10: phase-correct PWM, TOP = ICR1 */
#ifdef SERVO_MODE14
    /* The thesis' words, "Fast PWM mode 14", with the same ICR1/OCR1A (digest
     * §1): 100 Hz and 0.75 ms / 1.0 ms pulses instead of 50 Hz, 1.5 / 2.0 ms. */
    TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS11); /* mode 14: fast PWM, TOP = ICR1; clk/8 */
#else
    TCCR1B = _BV(WGM13) | _BV(CS11);             /* clk/8 */
#endif
}

/* --- commands -------------------------------------------------------------------- */
static void g00(void)
{
    const count_t sx = rx_count(), sy = rx_count();
    const uint8_t ocr0 = rx(), ocr2 = rx(), start = rx();
    pen(PEN_UP_OCR);
    OCR0A = ocr0;
    OCR2A = ocr2;
    cli();
    x_left = sx;
    x_half = 0;
    x_end_disables = 1;
    TIFR0 = _BV(OCF0A);
    TIFR2 = _BV(OCF2A);
    TIMSK0 = sx != 0 ? _BV(OCIE0A) : 0;
    apply_start(start);
    sei();
    timers_run();
    count_y_polled(sy);
    PORTB |= _BV(Y_EN);
    wait_zero(&x_left);
    PORTB |= _BV(X_EN);
    tx(ACK);
}

static void g01(void)
{
    const count_t sx = rx_count();
#ifdef IMPROVED
    const count_t sy = rx_count();
#endif
    const uint8_t ocr0 = rx(), ocr2 = rx(), start = rx();
    pen(PEN_DOWN_OCR);
    OCR0A = ocr0;
    OCR2A = ocr2;
    TIFR0 = _BV(OCF0A);
    TIFR2 = _BV(OCF2A);
#ifdef IMPROVED
    cli();
    y_left = sy;
    y_half = 0;
    TIMSK2 = sy != 0 ? _BV(OCIE2A) : 0;
    sei();
#endif
    apply_start(start);
    timers_run();
#ifdef G01_TIMER2_AS_WRITTEN
    /* Appendix A3's G_01: TCCR2B = 0b00000110 - clk/256 on Timer2 (its
     * comment says 128), where every other move and the PC's OCR2A use 1024. */
    TCCR2B = _BV(CS22) | _BV(CS21);
#endif
    count_x_polled(sx);
#ifdef IMPROVED
    PORTB |= _BV(X_EN);
    wait_zero(&y_left);
#endif
    PORTB |= _BV(X_EN) | _BV(Y_EN); /* faithful: Y stops with X, wherever it is */
    tx(ACK);
}

static void arc(void)
{
    pen(PEN_DOWN_OCR);
#ifdef IMPROVED
    x_end_disables = 1; /* each axis stops at its count: no run-on between chords */
#else
    x_end_disables = 0; /* the thesis: the motors turn on until the next chord loads */
#endif
    timers_run();
    for (;;) {
        /* received while the last chord runs */
        const uint8_t dx = rx();
#ifdef IMPROVED
        const uint8_t dy = rx();
#endif
        const uint8_t vx = rx(), vy = rx(), dir = rx();
        wait_zero(&x_left);
#ifdef IMPROVED
        wait_zero(&y_left);
#endif
        cli();
        x_left = dx;
        x_half = 0;
        OCR0A = vx;
        OCR2A = vy;
        apply_start(dir);
        TIFR0 = _BV(OCF0A);
        TIMSK0 = dx != 0 ? _BV(OCIE0A) : 0;
#ifdef IMPROVED
        y_left = dy;
        y_half = 0;
        TIFR2 = _BV(OCF2A);
        TIMSK2 = dy != 0 ? _BV(OCIE2A) : 0;
#endif
        sei();
        tx(ACK);
        if ((dir & (_BV(X_EN) | _BV(Y_EN))) == (_BV(X_EN) | _BV(Y_EN))) return; /* the closing record */
    }
}

static void m30(void)
{
    PORTB |= _BV(X_EN) | _BV(Y_EN);
    pen(PEN_UP_OCR);
#ifndef IMPROVED
    /* The thesis says only that M30 disables the drivers and sleeps; its
     * acceptance check (digest §8 item 15) wants the pen up. Power-down stops
     * Timer1, and the new width only starts at the next 20 ms frame: give the
     * SG90 its 0.15 s to lift before the clock stops (the improved build's
     * pen() already waits). Ours, not the thesis's: without it the pen stayed
     * down (tests/cnc Cnc2Axis.M30DisablesSleepsAndLiftsThePen). */
    _delay_ms(200);
#endif
    /* TXC0 is still set from the last byte sent (it clears only by writing
     * 1 or by its ISR): clear it, or the wait below ends at once and the
     * ACK is cut off by the sleep. */
    UCSR0A |= _BV(TXC0);
    tx(ACK);
    while (!(UCSR0A & _BV(TXC0))) { /* let the ACK leave before the clock stops */
    }
    set_sleep_mode(SLEEP_MODE_PWR_DOWN);
    cli();
    sleep_enable();
    sleep_cpu();
}

/* --- homing ---------------------------------------------------------------------- */
static void home(void)
{
    apply_start(_BV(X_DIR) | _BV(Y_DIR)); /* both enabled, toward the origin */
    OCR0A = HOMING_OCR;
    OCR2A = HOMING_OCR;
    timers_run();
    uint8_t x_home = 0, y_home = 0;
#ifdef HOMING_AS_WRITTEN
    /* The thesis' order (digest §1): on a switch, wait the debounce with the
     * motor still stepping, re-read, and only then switch its driver off. */
    while (!(x_home && y_home)) {
        if (!x_home && (PIND & _BV(PD2))) {
            _delay_ms(2);
            if (PIND & _BV(PD2)) {
                PORTB |= _BV(X_EN);
                x_home = 1;
            }
        }
        if (!y_home && (PIND & _BV(PD3))) {
            _delay_ms(2);
            if (PIND & _BV(PD3)) {
                PORTB |= _BV(Y_EN);
                y_home = 1;
            }
        }
    }
#endif
    while (!(x_home && y_home)) {
        if (!x_home && (PIND & _BV(PD2))) {
            PORTB |= _BV(X_EN);
            _delay_ms(2);
            if (PIND & _BV(PD2)) x_home = 1;
            else PORTB &= (uint8_t)~_BV(X_EN); /* a bounce: go on */
        }
        if (!y_home && (PIND & _BV(PD3))) {
            PORTB |= _BV(Y_EN);
            _delay_ms(2);
            if (PIND & _BV(PD3)) y_home = 1;
            else PORTB &= (uint8_t)~_BV(Y_EN);
        }
    }
    homed = 1;
}

int main(void)
{
    DDRB |= _BV(PB0) | _BV(PB2) | _BV(PB3) | _BV(PB4) | _BV(PB5);
    PORTB |= _BV(X_EN) | _BV(Y_EN);
    DDRD |= _BV(PD6);
    DDRC |= 0x3F;
    PORTC = 0x05 | 0x28; /* 1/32 on both: X M0=1 M1=0 M2=1 (PC0..2), Y M2 M1 M0 on PC3..5 */
    TCCR0A = _BV(COM0A0) | _BV(WGM01); /* CTC, toggle OC0A */
    TCCR2A = _BV(COM2A0) | _BV(WGM21); /* CTC, toggle OC2A */
    uart_init();
    pen_init();
    sei();
    home();
    for (;;) {
        switch (rx()) {
            case 0x00: g00(); break;
            case 0x01: g01(); break;
            case 0x02:
            case 0x03: arc(); break;
            case 0x3B: m30(); break;
            default: tx(NAK); break;
        }
    }
}
