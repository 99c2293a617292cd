#include "fw_avr446.h"

#include <math.h>

#define ALPHA FW_AVR446_ALPHA
#define A_T_x100 ((long)(ALPHA * FW_AVR446_TIMER_HZ * 100))
#define T1_FREQ_148 ((int)((FW_AVR446_TIMER_HZ * 0.676) / 100))
#define A_SQ (long)(ALPHA * 2 * 10000000000)
#define A_x20000 (int)(ALPHA * 20000)

void fw_avr446_plan(fw_avr446_t *ramp, unsigned int steps, unsigned int accel, unsigned int decel, unsigned int speed)
{
    unsigned int max_s_lim, accel_lim;
    ramp->min_delay = A_T_x100 / speed;
    ramp->step_delay = (T1_FREQ_148 * sqrt(A_SQ / accel)) / 100;
    /* Steps to reach full speed, and the step deceleration must start at. */
    max_s_lim = (long)speed * speed / (long)(((long)A_x20000 * accel) / 100);
    if (max_s_lim == 0) max_s_lim = 1;
    accel_lim = ((long)steps * decel) / (accel + decel);
    if (accel_lim == 0) accel_lim = 1;
    if (accel_lim <= max_s_lim) ramp->decel_val = accel_lim - steps;
    else ramp->decel_val = -((long)max_s_lim * accel) / decel;
    if (ramp->decel_val == 0) ramp->decel_val = -1;
    ramp->decel_start = steps + ramp->decel_val;
    if (ramp->step_delay <= ramp->min_delay) {
        ramp->step_delay = ramp->min_delay;
        ramp->state = FW_AVR446_RUN;
    } else {
        ramp->state = FW_AVR446_ACCEL;
    }
    ramp->accel_count = 0;
    ramp->rest = 0;
    ramp->steps = 0;
}

void fw_avr446_plan_constant(fw_avr446_t *ramp, unsigned int steps, unsigned int speed)
{
    ramp->min_delay = A_T_x100 / speed;
    ramp->step_delay = ramp->min_delay;
    ramp->decel_start = steps; /* never decelerates: stops dead after the last step */
    ramp->decel_val = 0;
    ramp->state = FW_AVR446_RUN;
    ramp->accel_count = 0;
    ramp->rest = 0;
    ramp->steps = 0;
}

/* c_n = c_{n-1} - (2 c_{n-1} + rest) / (4 n + 1), the remainder carried. */
static unsigned int next_delay(fw_avr446_t *ramp)
{
    ramp->accel_count++;
    const long twice = (2 * (long)ramp->step_delay) + ramp->rest;
    const unsigned int delay = ramp->step_delay - (twice / (4 * ramp->accel_count + 1));
    ramp->rest = twice % (4 * ramp->accel_count + 1);
    return delay;
}

void fw_avr446_next(fw_avr446_t *ramp)
{
    unsigned int delay = ramp->step_delay;
    ramp->steps++;
    switch (ramp->state) {
        case FW_AVR446_ACCEL:
            delay = next_delay(ramp);
            if (ramp->steps >= ramp->decel_start) {
                ramp->accel_count = ramp->decel_val;
                ramp->state = FW_AVR446_DECEL;
            } else if (delay <= ramp->min_delay) {
                ramp->last_accel_delay = delay;
                delay = ramp->min_delay;
                ramp->rest = 0;
                ramp->state = FW_AVR446_RUN;
            }
            break;
        case FW_AVR446_RUN:
            delay = ramp->min_delay;
            if (ramp->steps >= ramp->decel_start) {
                if (ramp->decel_val == 0) {
                    ramp->state = FW_AVR446_STOP; /* a constant-speed move */
                } else {
                    ramp->accel_count = ramp->decel_val;
                    delay = ramp->last_accel_delay;
                    ramp->state = FW_AVR446_DECEL;
                }
            }
            break;
        case FW_AVR446_DECEL:
            delay = next_delay(ramp);
            if (ramp->accel_count >= 0) ramp->state = FW_AVR446_STOP;
            break;
        default:
            break;
    }
    ramp->step_delay = delay;
}
