/*
 * AVR446's linear speed controller (Atmel application note AVR446, "Linear
 * speed control of stepper motor", speed_cntr.c), its integer algorithm as
 * seed 003 §1.5-1.6 computes it, shared by the firmware that ramps a stepper:
 *
 *   c0 = 0.676 * f_t * sqrt(2 alpha / accel)          (the 0.676 correction)
 *   c_n = c_{n-1} - (2 c_{n-1} + rest) / (4 n + 1)    (remainder carried)
 *   accelerate -> run at min_delay = alpha f_t / speed -> decelerate
 *
 * alpha = FW_AVR446_ALPHA (2 pi / FW_AVR446_STEPS_PER_REV unless given),
 * f_t = FW_AVR446_TIMER_HZ (the step timer's clock); all compile-time, so the constants fold as in the note.
 * Speeds in 0.01 rad/s, accelerations in 0.01 rad/s^2, delays in timer ticks.
 *
 * Use from the step timer's compare ISR:
 *   OCRnA = ramp.step_delay;
 *   if (fw_avr446_stepping(&ramp)) { <step>; fw_avr446_next(&ramp); } else { <stop the timer> }
 */
#ifndef FW_AVR446_H
#define FW_AVR446_H

#include <stdint.h>

#ifndef FW_AVR446_STEPS_PER_REV
#define FW_AVR446_STEPS_PER_REV 200
#endif
#ifndef FW_AVR446_TIMER_HZ
#define FW_AVR446_TIMER_HZ 2000000
#endif
/* The step angle in rad; seed 003 §4.2 rounds 2 pi / 200 to 0.0314. */
#ifndef FW_AVR446_ALPHA
#define FW_AVR446_ALPHA (2 * 3.14159 / FW_AVR446_STEPS_PER_REV)
#endif

enum { FW_AVR446_STOP, FW_AVR446_ACCEL, FW_AVR446_RUN, FW_AVR446_DECEL };

typedef struct {
    volatile uint8_t state;
    volatile unsigned int step_delay; /* ticks until the next compare */
    unsigned int min_delay;           /* ticks per step at full speed */
    unsigned int decel_start;         /* the step at which deceleration begins */
    int decel_val;                    /* -(steps of deceleration) */
    int accel_count;
    unsigned int rest;
    unsigned int last_accel_delay;
    unsigned int steps;               /* steps taken in this move */
} fw_avr446_t;

/* A ramped move of `steps` (>= 1). */
void fw_avr446_plan(fw_avr446_t *ramp, unsigned int steps, unsigned int accel, unsigned int decel, unsigned int speed);
/* `steps` at `speed` from the first step, stopping dead (no ramp). */
void fw_avr446_plan_constant(fw_avr446_t *ramp, unsigned int steps, unsigned int speed);
/* Whether the motor steps at this compare (else the move is over). */
static inline uint8_t fw_avr446_stepping(const fw_avr446_t *ramp) { return ramp->state != FW_AVR446_STOP; }
/* After the step: counts it and computes step_delay for the next interval. */
void fw_avr446_next(fw_avr446_t *ramp);

#endif
