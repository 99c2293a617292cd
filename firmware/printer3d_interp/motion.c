#include "motion.h"

#include <avr/interrupt.h>
#include <avr/sleep.h>
#include <util/atomic.h>

#define QUEUE_SIZE 4 /* a power of two */

volatile int32_t step_position[AXES];
volatile uint32_t ticks_total;
volatile int32_t arc_end_error_x, arc_end_error_y;
volatile uint8_t home_result;

static move_t queue[QUEUE_SIZE];
static volatile uint8_t head, tail; /* main pushes at head, the ISR pops at tail */
static volatile uint8_t running;    /* the ISR owns queue[tail] */

/* The executing move's state. */
static move_t cur;
static int32_t done;            /* executions of cur so far */
static uint32_t q1, q2;         /* DDA remainders */
static uint16_t e_acc;          /* extruder fraction, in SP_DEN parts */
static uint32_t remaining;      /* timer counts still to wait before the next tick (> 65536) */
static const uint8_t step_bit[AXES] = {X_STEP, Y_STEP, Z_STEP, E_STEP};

static void set_dir(uint8_t axis, int8_t sign)
{
    if (sign > 0) DIR_PORT |= DIR_BIT(axis);
    else DIR_PORT &= (uint8_t)~DIR_BIT(axis);
}

/* Waits `counts` timer counts (0.5 us each) before the next tick: Timer1 in
 * CTC at clk/8 counts to OCR1A; longer waits go in 65536-count pieces. */
static void arm(uint32_t counts)
{
    if (counts < 2) counts = 2;
    if (counts > 65536UL) {
        remaining = counts - 65536UL;
        OCR1A = 65535;
    } else {
        remaining = 0;
        OCR1A = (uint16_t)(counts - 1);
    }
}

static uint32_t interval_before(int32_t n)
{
    if (!cur.ramp) return cur.dtc_half_us;
#ifdef THESIS_DDA
    /* Code 4.7-4.8 as printed, in 16-bit unsigned ints and microseconds:
     * the ramp up has precedence, `total - N` wraps below N ticks (no ramp
     * down at all), the ramps overlap below 2N, and N * dt_const wraps
     * above 1310 us (digest §3). */
    const unsigned int total = (unsigned int)cur.ticks, k = (unsigned int)n;
    const unsigned int dt_const_us = (unsigned int)(cur.dtc_half_us / 2);
    unsigned int dt_us;
    if (k < RAMP_N) dt_us = (unsigned int)(RAMP_N * dt_const_us) / k;
    else if (k > total - RAMP_N) dt_us = (unsigned int)(RAMP_N * dt_const_us) / (total - k + 1);
    else dt_us = dt_const_us;
    return 2UL * dt_us;
#else
    int32_t k = n;
    if (cur.ticks - n + 1 < k) k = cur.ticks - n + 1;
    if (k >= RAMP_N) return cur.dtc_half_us;
    return (uint32_t)RAMP_N * cur.dtc_half_us / (uint32_t)k;
#endif
}

/* Loads queue[tail] into cur, or stops the timer when the queue is empty. */
static void start_next(void)
{
    if (tail == head) {
        running = 0;
        TCCR1B = _BV(WGM12); /* stopped */
        TIMSK1 = 0;
        return;
    }
    cur = queue[tail & (QUEUE_SIZE - 1)];
    tail = (uint8_t)(tail + 1);
    running = 1;
    done = 0;
    q1 = q2 = 0;
    arm(interval_before(1));
}

/* DIR for a new move is set at its first tick, a whole interval after the
 * previous move's last STEP edge: a drive board reads DIR in its INT0
 * routine, which may start late (behind its ADC interrupt), so DIR must not
 * change right after an edge. */
static void apply_dirs(void)
{
    if (cur.kind == MOVE_LINE) {
        set_dir(cur.axis_a, cur.a >= 0 ? 1 : -1);
        if (cur.axis_b < AXES) set_dir(cur.axis_b, cur.b >= 0 ? 1 : -1);
    } else if (cur.kind == MOVE_BURST || cur.kind == MOVE_HOME) {
        set_dir(cur.axis_a, cur.a >= 0 ? 1 : -1);
    }
    if (cur.extrude) set_dir(AXIS_E, 1);
}

static void kick(void)
{
    if (running) return;
    start_next();
    if (!running) return;
    TCNT1 = 0;
    TIFR1 = _BV(OCF1A);
    TIMSK1 = _BV(OCIE1A);
    TCCR1B = _BV(WGM12) | _BV(CS11); /* CTC, clk/8: 0.5 us per count */
}

static int32_t iabs32(int32_t v) { return v < 0 ? -v : v; }

/* One execution of the circular DDA: Y advances with |px|, X with |py|. */
static uint8_t arc_tick(void)
{
    uint8_t steps = 0;
    q1 += (uint32_t)iabs32(cur.px);
    if (q1 >= (uint32_t)cur.radius) {
        q1 -= (uint32_t)cur.radius;
        /* CW: up on the left of the centre; CCW: down there. */
        const int8_t dy = (cur.px < 0) == (cur.cw != 0) ? 1 : -1;
        set_dir(AXIS_Y, dy);
        cur.py += dy;
        step_position[AXIS_Y] += dy;
        steps |= Y_STEP;
    }
    q2 += (uint32_t)iabs32(cur.py);
    if (q2 >= (uint32_t)cur.radius) {
        q2 -= (uint32_t)cur.radius;
        /* CW: right above the centre; CCW: left there. */
        const int8_t dx = (cur.py > 0) == (cur.cw != 0) ? 1 : -1;
        set_dir(AXIS_X, dx);
        cur.px += dx;
        step_position[AXIS_X] += dx;
        steps |= X_STEP;
    }
    return steps;
}

static uint8_t line_tick(void)
{
    uint8_t steps = 0;
    const uint32_t l = (uint32_t)cur.ticks;
    q1 += (uint32_t)iabs32(cur.a);
    if (q1 >= l) {
        q1 -= l;
        steps |= step_bit[cur.axis_a];
        step_position[cur.axis_a] += cur.a >= 0 ? 1 : -1;
    }
    if (cur.axis_b < AXES) {
        q2 += (uint32_t)iabs32(cur.b);
        if (q2 >= l) {
            q2 -= l;
            steps |= step_bit[cur.axis_b];
            step_position[cur.axis_b] += cur.b >= 0 ? 1 : -1;
        }
    }
    return steps;
}

/* After an arc: the DDA ends within a BLU or two of the target (the
 * thesis accepts "a neighbouring grid point"); the rest is a short line. */
static uint8_t arc_fixup(void)
{
    const int32_t ex = cur.end_x - step_position[AXIS_X];
    const int32_t ey = cur.end_y - step_position[AXIS_Y];
    arc_end_error_x = ex;
    arc_end_error_y = ey;
    if (ex == 0 && ey == 0) return 0;
    cur.kind = MOVE_LINE;
    cur.axis_a = AXIS_X;
    cur.axis_b = AXIS_Y;
    cur.a = ex;
    cur.b = ey;
    cur.ticks = iabs32(ex) > iabs32(ey) ? iabs32(ex) : iabs32(ey);
    cur.extrude = 0;
    cur.ramp = 0;
    done = 0;
    q1 = q2 = 0;
    arm(cur.dtc_half_us);
    return 1;
}

ISR(TIMER1_COMPA_vect)
{
    if (remaining) {
        if (remaining > 65536UL) {
            remaining -= 65536UL;
        } else {
            OCR1A = (uint16_t)(remaining - 1);
            remaining = 0;
        }
        return;
    }
    STEP_PORT |= TICK_PIN;
    if (done == 0) apply_dirs();
    uint8_t steps = 0;
    switch (cur.kind) {
        case MOVE_LINE: steps = line_tick(); break;
        case MOVE_ARC: steps = arc_tick(); break;
        case MOVE_BURST:
            steps = step_bit[cur.axis_a];
            step_position[cur.axis_a] += cur.a >= 0 ? 1 : -1;
            break;
        case MOVE_HOME:
            if (!(SWITCH_PIN & SWITCH_BIT(cur.axis_a))) { /* closed: home */
                home_result = 1;
                done = cur.ticks - 1;
                break;
            }
            steps = step_bit[cur.axis_a];
            step_position[cur.axis_a] += cur.a >= 0 ? 1 : -1;
            if (done + 1 == cur.ticks) home_result = 2;
            break;
    }
    if (cur.extrude) {
        e_acc += SP_NUM;
        if (e_acc >= SP_DEN) {
            e_acc -= SP_DEN;
            steps |= E_STEP;
            ++step_position[AXIS_E];
        }
    }
    STEP_PORT |= steps; /* DIR was set before, in an earlier instruction */
    ++ticks_total;
    ++done;
    if (done < cur.ticks) {
        arm(interval_before(done + 1));
#ifdef THESIS_DDA
    } else if (1) { /* the thesis counts the arc's length and stops: no fix-up */
        start_next();
#endif
    } else if (!(cur.kind == MOVE_ARC && arc_fixup())) {
        start_next();
    }
    STEP_PORT &= (uint8_t)~(steps | TICK_PIN);
}

void motion_init(void)
{
    STEP_DDR |= X_STEP | Y_STEP | Z_STEP | E_STEP | TICK_PIN;
    DIR_DDR = 0xFF;
    DIR_PORT = ENABLE_BITS; /* enabled, DIR low */
    SWITCH_PORT |= SWITCH_BIT(AXIS_X) | SWITCH_BIT(AXIS_Y) | SWITCH_BIT(AXIS_Z);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12);
    TCCR3A = 0;
    TCCR3B = _BV(CS32) | _BV(CS30); /* free-running, clk/1024 */
}

/* Idle sleep until the next interrupt with interrupts on; the caller
 * re-checks its condition. SEI before SLEEP lets exactly the SLEEP run
 * before a pending interrupt (2560 §7.8), so no wake-up is missed. */
static uint8_t queue_full(void) { return (uint8_t)(head - tail) >= QUEUE_SIZE; }

void (*motion_keepalive)(void);

/* Sleeps while `busy()`, calling motion_keepalive about once a second. */
static void nap_while(uint8_t (*busy)(void))
{
    uint16_t last = TCNT3;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) {
        cli();
        if (!busy()) break;
        sleep_enable();
        sei();
        sleep_cpu(); /* a tick comes at least every 65 ms while a move runs */
        sleep_disable();
        if ((uint16_t)(TCNT3 - last) >= 15625U) { /* Timer3: 15625 counts per second */
            last = TCNT3;
            if (motion_keepalive) motion_keepalive();
        }
    }
    sei();
}

void motion_push(const move_t *m)
{
    nap_while(queue_full);
    queue[head & (QUEUE_SIZE - 1)] = *m;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE)
    {
        head = (uint8_t)(head + 1);
        kick();
    }
}

uint8_t motion_busy(void) { return running || head != tail; }

void motion_wait_idle(void)
{
    nap_while(motion_busy);
}

EMPTY_INTERRUPT(TIMER3_COMPA_vect); /* a wake-up for motion_sleep_ms */

void motion_sleep_ms(uint32_t ms)
{
    /* Timer3 runs free at 15625 counts per second: at most 4 s per wait. */
    while (ms > 0) {
        const uint16_t chunk = ms > 4000 ? 4000 : (uint16_t)ms;
        ms -= chunk;
        const uint16_t counts = (uint16_t)(((uint32_t)chunk * 15625UL + 500) / 1000);
        const uint16_t start = TCNT3;
        OCR3A = (uint16_t)(start + counts);
        TIFR3 = _BV(OCF3A);
        TIMSK3 |= _BV(OCIE3A);
        set_sleep_mode(SLEEP_MODE_IDLE);
        for (;;) {
            cli();
            if ((uint16_t)(TCNT3 - start) >= counts) break;
            sleep_enable();
            sei();
            sleep_cpu();
            sleep_disable();
        }
        TIMSK3 &= (uint8_t)~_BV(OCIE3A);
        sei();
    }
}

void motion_set_position(uint8_t axis, int32_t blu)
{
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { step_position[axis] = blu; }
}
