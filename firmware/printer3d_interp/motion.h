/*
 * The interpolation engine (seed 001 ch. 4): a queue of moves executed by
 * the Timer1 compare interrupt, one interpolation execution ("tick") per
 * interrupt: the linear DDA (Code 4.1-4.3) and the circular DDA (Code
 * 4.4-4.6) in 32-bit integers, path speed one BLU per tick, and the dynamic
 * dT profile (Code 4.7-4.8, §4.9): the interval before tick n of an L-tick
 * move is N dT_c / min(n, L - n + 1, N), so the pulse pattern never changes,
 * only the spacing (Appendix A's reference model; the listing's own
 * arithmetic underflows for moves shorter than N, which the min avoids).
 */
#ifndef PRINTER3D_INTERP_MOTION_H
#define PRINTER3D_INTERP_MOTION_H

#include <stdint.h>

#include "config.h"

enum move_kind { MOVE_LINE, MOVE_ARC, MOVE_BURST, MOVE_HOME };

typedef struct {
    uint8_t kind;
    uint8_t axis_a, axis_b;  /* LINE: the two axes of the DDA (axis_b may equal AXES: none) */
    uint8_t extrude;         /* SP extruder steps per tick ride along */
    uint8_t cw;              /* ARC: G02 */
    int32_t a, b;            /* LINE: signed BLU on axis_a / axis_b; BURST/HOME: signed steps on axis_a */
    int32_t ticks;           /* executions: L for lines, round(R * angle) for arcs */
    int32_t px, py, radius;  /* ARC: start relative to the centre, R */
    int32_t end_x, end_y;    /* ARC: the target, absolute BLU */
    uint32_t dtc_half_us;    /* constant-speed tick interval in 0.5 us (timer counts) */
    uint8_t ramp;            /* apply the dynamic dT profile */
} move_t;

/* Absolute position in BLU (E: steps) as the step pulses left the MCU. */
extern volatile int32_t step_position[AXES];
/* Executions so far, over all moves, and the last arc's DDA end error
 * (target - reached, BLU, before the fix-up move). */
extern volatile uint32_t ticks_total;
extern volatile int32_t arc_end_error_x, arc_end_error_y;
/* 1 once a homing move stopped on its switch, 2 when it gave up. */
extern volatile uint8_t home_result;

void motion_init(void);
/* Sleeps until a queue slot is free, then queues `m`. */
void motion_push(const move_t *m);
/* Sleeps until every queued move has run. */
void motion_wait_idle(void);
/* Called about once a second while motion_push or motion_wait_idle waits
 * (Timer3 at clk/1024 runs free as the time base), so the host hears a
 * keep-alive; NULL for none. */
extern void (*motion_keepalive)(void);
/* Sleeps (idle mode) for `ms` milliseconds, to Timer3's 64 us resolution;
 * interrupts (the UART, move ticks) are served meanwhile. */
void motion_sleep_ms(uint32_t ms);
uint8_t motion_busy(void);
/* Sets step_position[axis] while idle (G92, homing). */
void motion_set_position(uint8_t axis, int32_t blu);

#endif
