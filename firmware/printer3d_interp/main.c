/*
 * printer3d_interp - seed 001's interpolation system (ch. 4) on an
 * ATmega2560 at 16 MHz, driving the four drive boards (firmware/
 * printer3d_drive) by STEP/DIR/ENABLE and the heater MCU (firmware/
 * printer3d_heater) over TWI, with G-code from a host on USART0.
 *
 * Host protocol (the thesis leaves the link open, digest §2; ours follows
 * the RepRap hosts' Marlin dialect, so pronsole and OctoPrint can drive it):
 * 115200 baud 8N1; "start" after reset; every line is answered by exactly
 * one "ok" (reporting commands print before it); a bad line first prints
 * "Error:<reason>" and, for a wrong checksum or line number, "Resend: N".
 * Lines: up to 95 characters without comments; N<line> and *<checksum>
 * (XOR of the bytes before '*') are checked when present; M110 N sets the
 * line number.
 *
 * G-code: G0/G1 X Y Z F (F in mm/min, modal; Z moves run alone, before the
 * XY part, as §4.8 says), G2/G3 X Y with I J (centre offset) or R (the
 * shorter arc, or the longer for R < 0; any angle up to a full circle), G4
 * P<ms>/S<s>, G20/G21, G28 [X Y Z] (to the min switches), G90/G91, G92,
 * M3/M03 extruder on (SP steps per tick during G1/G2/G3, §4.7), M5 off (with
 * the anti-ooze retract), M17/M18/M84, M82/M83 (accepted), M104/M109 S<degC>,
 * M105, M114, M115, M400. E words are accepted and ignored: the extruder
 * follows the path (§4.7).
 *
 * THESIS_PARSER builds Code 4.11's parser as printed instead (thesis_parser.c).
 *
 * Globals for tests: see motion.h, and plan_position, lines_ok, lines_bad.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "avrbench_mcu.h"
#include "config.h"
#include "fw_uart.h"
#include "gcode.h"
#include "heater_link.h"
#include "interp.h"
#include "motion.h"

AVRBENCH_MCU_SECTION();

volatile int32_t plan_position[AXES]; /* BLU; E: steps */
volatile uint16_t lines_ok, lines_bad;

static uint8_t absolute = 1, inches = 0;
static int8_t motion_mode = -1; /* 0..3 once a G0..G3 was seen */
static int32_t feed_milli = DEFAULT_FEED_MM_MIN * 1000L;
static uint8_t extruder_on, retracted = 1;

void reply(const char *s)
{
    fw_uart_puts(s);
    fw_uart_putc('\n');
}

/* Marlin's host keep-alive while a command waits: hosts re-arm their timeouts. */
static void busy(void) { reply("echo:busy: processing"); }

/* A line that cannot run: "Error:<why>", then the "ok" that frees the host's slot. */
static void fail(const char *why)
{
    ++lines_bad;
    fw_uart_puts("Error:");
    reply(why);
    reply("ok");
}

/* A length in thousandths of mm (or inch) to BLU, rounded. */
static int32_t to_blu(int32_t milli)
{
    const int64_t scaled = (int64_t)milli * BLU_PER_MM * (inches ? 254 : 10);
    const int64_t den = 10000;
    return (int32_t)(scaled >= 0 ? (scaled + den / 2) / den : -((-scaled + den / 2) / den));
}

uint32_t dtc_from_feed(int32_t feed_milli_mm_min)
{
    /* One BLU per tick at F mm/min: F * BLU_PER_MM / 60 ticks per second, in 0.5 us counts. */
    return (uint32_t)(120000000000LL / ((int64_t)feed_milli_mm_min * BLU_PER_MM));
}

static uint32_t isqrt64(uint64_t v)
{
    uint64_t r = 0, bit = 1ULL << 62;
    while (bit > v) bit >>= 2;
    while (bit) {
        if (v >= r + bit) {
            v -= r + bit;
            r = (r >> 1) + bit;
        } else {
            r >>= 1;
        }
        bit >>= 2;
    }
    if (v > r) ++r; /* round to nearest: r^2 + r < v0 */
    return (uint32_t)r;
}

static void burst(uint8_t axis, int32_t steps)
{
    move_t m = {0};
    m.kind = MOVE_BURST;
    m.axis_a = axis;
    m.axis_b = AXES;
    m.a = steps;
    m.ticks = labs(steps);
    m.dtc_half_us = 2 * BURST_PERIOD_US;
    motion_push(&m);
}

static void retract(void)
{
    if (retracted) return;
    burst(AXIS_E, -RETRACT_STEPS);
    plan_position[AXIS_E] -= RETRACT_STEPS;
    retracted = 1;
}

static void prime(void)
{
    if (!retracted) return;
    burst(AXIS_E, RETRACT_STEPS);
    plan_position[AXIS_E] += RETRACT_STEPS;
    retracted = 0;
}

/* A depositing move primes a retracted extruder and carries SP steps per
 * tick; any other move retracts an extruder that is on (§4.7). */
static void extruder_for(move_t *m, uint8_t deposit)
{
    if (deposit) {
        prime();
        m->extrude = 1;
        plan_position[AXIS_E] += (int32_t)(((int64_t)m->ticks * SP_NUM) / SP_DEN); /* planned */
    } else if (extruder_on) {
        retract();
    }
}

void queue_line(uint8_t axis_a, int32_t a, uint8_t axis_b, int32_t b, uint32_t dtc, uint8_t deposit)
{
    move_t m = {0};
    m.kind = MOVE_LINE;
    m.axis_a = axis_a;
    m.axis_b = axis_b;
    m.a = a;
    m.b = b;
#ifdef THESIS_DDA
    /* Code 4.1 as printed: L = round(sqrt(_a*_a + _b*_b)) with 16-bit ints
     * (an int is 16 bits on the AVR): a square above 32767 wraps, so L is
     * too short once |a| > 181 BLU and the DDA, one pulse per tick at most,
     * runs short of |a| (digest §3). */
    const unsigned int square = (unsigned int)(int16_t)a * (unsigned int)(int16_t)a +
                                (unsigned int)(int16_t)b * (unsigned int)(int16_t)b;
    m.ticks = (uint16_t)lround(sqrt((double)(int)square));
#else
    int32_t l = (int32_t)isqrt64((uint64_t)((int64_t)a * a + (int64_t)b * b));
    if (l < labs(a)) l = labs(a); /* L >= each component: exactly |a| and |b| pulses in L ticks */
    if (l < labs(b)) l = labs(b);
    m.ticks = l;
#endif
    m.dtc_half_us = dtc;
    m.ramp = 1;
    extruder_for(&m, deposit);
    motion_push(&m);
}

const char *queue_arc(int32_t ci, int32_t cj, int32_t x, int32_t y, uint8_t cw, uint32_t dtc, uint8_t deposit)
{
    const int32_t sx = plan_position[AXIS_X], sy = plan_position[AXIS_Y];
    const int32_t radius = (int32_t)isqrt64((uint64_t)((int64_t)ci * ci + (int64_t)cj * cj));
    const float ex = (float)(x - sx - ci), ey = (float)(y - sy - cj);
    const float end_r = sqrtf(ex * ex + ey * ey);
    if (radius < 1 || fabsf(end_r - (float)radius) > 2.0f + 0.001f * (float)radius) {
        return "arc end point not on the circle";
    }
#ifdef THESIS_DDA
    /* Code 4.6 as printed: the arc's length from its chord AB, theta =
     * arcsin(AB / 2R), s = 2 theta R: at most a half circle (a 270-degree
     * arc runs 90 degrees), nothing for a whole one (AB = 0, no tick). */
    const float chord_x = (float)(x - sx), chord_y = (float)(y - sy);
    const float sweep = 2.0f * asinf(sqrtf(chord_x * chord_x + chord_y * chord_y) / 2.0f / (float)radius);
#else
    /* The swept angle, from the start and end angles about the centre:
     * any angle up to a full circle (end = start), which the thesis'
     * arcsin-based length cannot give. */
    const float a0 = atan2f((float)-cj, (float)-ci), a1 = atan2f(ey, ex);
    float sweep = cw ? a0 - a1 : a1 - a0;
    while (sweep <= 1e-6f) sweep += 2.0f * (float)M_PI;
    while (sweep > 2.0f * (float)M_PI + 1e-6f) sweep -= 2.0f * (float)M_PI;
#endif
    move_t m = {0};
    m.kind = MOVE_ARC;
    m.cw = cw;
    m.px = -ci;
    m.py = -cj;
    m.radius = radius;
    m.ticks = lroundf(sweep * (float)radius);
#ifdef THESIS_DDA
    if (m.ticks < 1) { /* the DDA loop runs no tick */
        plan_position[AXIS_X] = x;
        plan_position[AXIS_Y] = y;
        return 0;
    }
#endif
    if (m.ticks < 1) m.ticks = 1;
    m.end_x = x;
    m.end_y = y;
    m.dtc_half_us = dtc;
    m.ramp = 1;
    extruder_for(&m, deposit);
    motion_push(&m);
    plan_position[AXIS_X] = x;
    plan_position[AXIS_Y] = y;
    return 0;
}

static uint8_t target_of(const words_t *w, char letter, uint8_t axis, int32_t *out)
{
    if (!(w->present & WORD_BIT(letter))) {
        *out = plan_position[axis];
        return 1;
    }
    const int32_t v = to_blu(w->milli[letter - 'A']);
    *out = absolute ? v : plan_position[axis] + v;
    return labs(*out) <= MAX_ABS_MM * BLU_PER_MM;
}

static void linear(const words_t *w, uint8_t rapid)
{
    int32_t x, y, z;
    if (!target_of(w, 'X', AXIS_X, &x) || !target_of(w, 'Y', AXIS_Y, &y) || !target_of(w, 'Z', AXIS_Z, &z)) {
        fail("target out of range");
        return;
    }
    const uint32_t dtc = dtc_from_feed(rapid ? MAX_FEED_MM_MIN * 1000L : feed_milli);
    const int32_t dz = z - plan_position[AXIS_Z];
    if (dz != 0) { /* Z alone first (§4.8): nothing else moves */
        queue_line(AXIS_Z, dz, AXES, 0, dtc, 0);
        plan_position[AXIS_Z] = z;
    }
    const int32_t dx = x - plan_position[AXIS_X], dy = y - plan_position[AXIS_Y];
    if (dx != 0 || dy != 0) {
        queue_line(AXIS_X, dx, AXIS_Y, dy, dtc, !rapid && extruder_on);
        plan_position[AXIS_X] = x;
        plan_position[AXIS_Y] = y;
    }
    reply("ok");
}

static void arc(const words_t *w, uint8_t cw)
{
    int32_t x, y, z;
    if (!target_of(w, 'X', AXIS_X, &x) || !target_of(w, 'Y', AXIS_Y, &y) || !target_of(w, 'Z', AXIS_Z, &z)) {
        fail("target out of range");
        return;
    }
    if (z != plan_position[AXIS_Z]) {
        fail("helical arcs are not supported");
        return;
    }
    const int32_t sx = plan_position[AXIS_X], sy = plan_position[AXIS_Y];
    const float dx = (float)(x - sx), dy = (float)(y - sy);
    float i, j;
    if (w->present & WORD_BIT('R')) {
        /* §4.6.4.1: the centre on the chord's bisector, CK from it. */
        const float r = (float)to_blu(w->milli['R' - 'A']);
        const float ab = sqrtf(dx * dx + dy * dy);
        const float ck2 = r * r - ab * ab / 4;
        if (ab == 0 || ck2 < -1.0f) {
            fail("arc radius too small for its end point");
            return;
        }
        float ck = ck2 > 0 ? sqrtf(ck2) : 0;
        /* The shorter arc has its centre to the right of the chord for G2. */
        if ((r < 0) != (cw != 0)) ck = -ck;
        i = dx / 2 - dy / ab * ck;
        j = dy / 2 + dx / ab * ck;
    } else if (w->present & (WORD_BIT('I') | WORD_BIT('J'))) {
        i = (float)to_blu(w->milli['I' - 'A']);
        j = (float)to_blu(w->milli['J' - 'A']);
    } else {
        fail("arc needs I/J or R");
        return;
    }
    const char *why = queue_arc((int32_t)lroundf(i), (int32_t)lroundf(j), x, y, cw, dtc_from_feed(feed_milli),
                                extruder_on);
    if (why) {
        fail(why);
        return;
    }
    reply("ok");
}

/* Homes the axes in `mask` (bit 0 X, 1 Y, 2 Z) in that order; 0 when a
 * switch never closed. */
static uint8_t home_axes(uint8_t mask)
{
    motion_wait_idle();
    for (uint8_t axis = AXIS_X; axis <= AXIS_Z; ++axis) {
        if (!(mask & (1 << axis))) continue;
        move_t m = {0};
        m.kind = MOVE_HOME;
        m.axis_a = axis;
        m.axis_b = AXES;
        m.a = -HOMING_MAX_BLU;
        m.ticks = HOMING_MAX_BLU;
        m.dtc_half_us = 2 * HOMING_PERIOD_US;
        home_result = 0;
        motion_push(&m);
        motion_wait_idle();
        if (home_result != 1) return 0;
        motion_set_position(axis, 0);
        plan_position[axis] = 0;
    }
    return 1;
}

void home_all(void) { home_axes(7); }

static void home(const words_t *w)
{
    uint8_t mask = (uint8_t)(((w->present & WORD_BIT('X')) ? 1 : 0) | ((w->present & WORD_BIT('Y')) ? 2 : 0) |
                             ((w->present & WORD_BIT('Z')) ? 4 : 0));
    if (!home_axes(mask ? mask : 7)) {
        fail("homing failed: no limit switch");
        return;
    }
    reply("ok");
}

void set_extruder(uint8_t on)
{
    extruder_on = on;
    if (!on) retract();
}

static void print_mm(char axis, int32_t blu)
{
    fw_uart_putc(axis);
    fw_uart_putc(':');
    if (blu < 0) {
        fw_uart_putc('-');
        blu = -blu;
    }
    fw_uart_put_u32((uint32_t)(blu / BLU_PER_MM));
    fw_uart_putc('.');
    uint32_t frac = (uint32_t)(blu % BLU_PER_MM) * (1000UL / BLU_PER_MM);
    fw_uart_putc((char)('0' + frac / 100));
    fw_uart_putc((char)('0' + frac / 10 % 10));
    fw_uart_putc((char)('0' + frac % 10));
}

static void print_temperature(const heater_status_t *s)
{
    fw_uart_puts("T:");
    int16_t t = s->temp_x10;
    if (t < 0) {
        fw_uart_putc('-');
        t = (int16_t)-t;
    }
    fw_uart_put_u32((uint32_t)(t / 10));
    fw_uart_putc('.');
    fw_uart_putc((char)('0' + t % 10));
    fw_uart_puts(" /");
    fw_uart_put_u32(s->setpoint_c);
    fw_uart_puts(".0");
}

static void temperature(const words_t *w, uint8_t wait)
{
    if (!(w->present & WORD_BIT('S'))) {
        fail("M104/M109 need S");
        return;
    }
    const int32_t s = w->milli['S' - 'A'] / 1000;
    if (s < 0 || s > 300) {
        fail("temperature out of range (0..300)");
        return;
    }
    if (!heater_set((uint16_t)s)) {
        fail("heater link");
        return;
    }
    if (wait && s > 0) {
        heater_status_t st;
        for (;;) {
            if (!heater_read(&st)) {
                fail("heater link");
                return;
            }
            if (st.temp_ok) break;
            print_temperature(&st); /* a keep-alive each second */
            fw_uart_putc('\n');
            motion_sleep_ms(1000);
        }
    }
    reply("ok");
}

static void set_position(const words_t *w)
{
    motion_wait_idle();
    static const char letters[3] = {'X', 'Y', 'Z'};
    for (uint8_t axis = AXIS_X; axis <= AXIS_Z; ++axis) {
        if (!(w->present & WORD_BIT(letters[axis]))) continue;
        const int32_t v = to_blu(w->milli[letters[axis] - 'A']);
        plan_position[axis] = v;
        motion_set_position(axis, v);
    }
    reply("ok");
}

static void dwell(const words_t *w)
{
    motion_wait_idle();
    int32_t ms = 0;
    if (w->present & WORD_BIT('P')) ms = w->milli['P' - 'A'] / 1000;
    if (w->present & WORD_BIT('S')) ms = w->milli['S' - 'A'];
    if (ms > 0) motion_sleep_ms((uint32_t)ms);
    reply("ok");
}

static void m_code(const words_t *w)
{
    switch (w->m) {
        case 3: set_extruder(1); reply("ok"); return;
        case 5: set_extruder(0); reply("ok"); return;
        case 17: DIR_PORT |= ENABLE_BITS; reply("ok"); return;
        case 18:
        case 84:
            motion_wait_idle();
            DIR_PORT &= (uint8_t)~ENABLE_BITS;
            reply("ok");
            return;
        case 82:
        case 83: reply("ok"); return;
        case 104: temperature(w, 0); return;
        case 109: temperature(w, 1); return;
        case 105: {
            heater_status_t st;
            if (!heater_read(&st)) {
                fail("heater link");
                return;
            }
            fw_uart_puts("ok ");
            print_temperature(&st);
            fw_uart_putc('\n');
            return;
        }
        case 110: reply("ok"); return; /* the line number was taken in handle_line */
        case 114:
            print_mm('X', plan_position[AXIS_X]);
            fw_uart_putc(' ');
            print_mm('Y', plan_position[AXIS_Y]);
            fw_uart_putc(' ');
            print_mm('Z', plan_position[AXIS_Z]);
            fw_uart_puts(" E:");
            fw_uart_put_i32(plan_position[AXIS_E]);
            fw_uart_putc('\n');
            reply("ok");
            return;
        case 115: reply("FIRMWARE_NAME:avrbench printer3d_interp (seed 001) PROTOCOL_VERSION:1.0"); reply("ok"); return;
        case 400: motion_wait_idle(); reply("ok"); return;
        default: fail("unknown M code"); return;
    }
}

static void g_code(int32_t g_milli, const words_t *w, uint8_t *moved)
{
    switch (g_milli) {
        case 0: motion_mode = 0; break;
        case 1000: motion_mode = 1; break;
        case 2000: motion_mode = 2; break;
        case 3000: motion_mode = 3; break;
        case 4000: dwell(w); *moved = 1; return;
        case 20000: inches = 1; return;
        case 21000: inches = 0; return;
        case 28000: home(w); *moved = 1; return;
        case 90000: absolute = 1; return;
        case 91000: absolute = 0; return;
        case 92000: set_position(w); *moved = 1; return;
        default: fail("unknown G code"); *moved = 1; return;
    }
}

void handle_words(const words_t *w)
{
    if (w->present & WORD_BIT('F')) {
        const int32_t f = w->milli['F' - 'A'];
        if (f < MIN_FEED_MM_MIN * 1000L) {
            fail("feed out of range");
            return;
        }
        feed_milli = f > MAX_FEED_MM_MIN * 1000L ? MAX_FEED_MM_MIN * 1000L : f;
    }
    if (w->m >= 0) {
        m_code(w);
        return;
    }
    uint8_t done = 0;
    for (uint8_t k = 0; k < w->g_count && !done; ++k) g_code(w->g[k], w, &done);
    if (done) return;
    const uint32_t axis_words = WORD_BIT('X') | WORD_BIT('Y') | WORD_BIT('Z');
    const uint32_t arc_words = axis_words | WORD_BIT('I') | WORD_BIT('J') | WORD_BIT('R');
    if (motion_mode >= 0 && (w->present & (motion_mode >= 2 ? arc_words : axis_words))) {
        if (motion_mode <= 1) linear(w, motion_mode == 0);
        else arc(w, motion_mode == 2);
        return;
    }
    if (w->g_count == 0 && !(w->present & (WORD_BIT('F') | WORD_BIT('E') | WORD_BIT('N')))) {
        fail("no command");
        return;
    }
    reply("ok");
}

#ifndef THESIS_PARSER
static line_reader_t reader;
static int32_t next_line = 1; /* N expected next */

/* Error and Resend for a line the host must send again. */
static void resend(const char *why)
{
    ++lines_bad;
    fw_uart_puts("Error:");
    reply(why);
    fw_uart_puts("Resend: ");
    fw_uart_put_i32(next_line);
    fw_uart_putc('\n');
    reply("ok");
}

static void handle_line(void)
{
    words_t w;
    if (reader.overflow) {
        fail("line too long");
        return;
    }
    const uint8_t parsed = parse_words(reader.text, &w);
    const uint8_t has_n = parsed == PARSE_OK && (w.present & WORD_BIT('N'));
    if (!line_checksum_ok(&reader) || (reader.star && !has_n)) {
        resend("checksum mismatch");
        return;
    }
    if (parsed != PARSE_OK) {
        fail(parsed == PARSE_BAD_NUMBER ? "bad number" : "bad word");
        return;
    }
    if (has_n) {
        if (w.m == 110) {
            next_line = w.n + 1;
        } else if (w.n != next_line) {
            resend("line number is not last line number + 1");
            return;
        } else {
            ++next_line;
        }
    }
    ++lines_ok;
    handle_words(&w);
}
#endif

int main(void)
{
    motion_init();
    motion_keepalive = busy;
    heater_link_init();
    fw_uart_init(16, 1); /* 115200 baud */
    sei();
    reply("start");
    for (;;) {
        const int16_t c = fw_uart_getc();
        if (c < 0) {
            fw_uart_idle();
            continue;
        }
#ifdef THESIS_PARSER
        thesis_feed((char)c);
#else
        if (line_feed(&reader, (char)c)) {
            handle_line();
            reader = (line_reader_t){0};
        }
#endif
    }
}
