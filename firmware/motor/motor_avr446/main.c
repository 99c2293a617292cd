/*
 * motor_avr446 - the linear speed controller of Atmel AVR446 ("Linear speed
 * control of stepper motor", speed_cntr.c), as seed 003 §1.5-1.6 and §4.2
 * compute it: the SM-42BYG011-25 on the Motor Shield's stepper port 2, two
 * phases on (DOUBLE), a 400-step move at 100 rad/s^2 acceleration and
 * deceleration up to 200 rpm (20.94 rad/s, the measured pull-out speed).
 *
 * AVR446's integer algorithm, unchanged but for the timer clock: Timer1 runs
 * at T1_FREQ = 16 MHz / 8 = 2 MHz (the note's 1 MHz example, seed 003 §4.2,
 * gives every delay in 1 us; here they are 0.5 us ticks, so each c_n is twice
 * the thesis table's). Speeds in 0.01 rad/s, accelerations in 0.01 rad/s^2:
 *   c0 = T1_FREQ_148 * sqrt(A_SQ / accel) / 100 = 33889 ticks (16.94 ms;
 *        thesis c0 = 16941 us)
 *   min_delay = A_T_x100 / speed = 3000 ticks (1.5 ms, 666.7 steps/s)
 *   max_s_lim = speed^2 / (A_x20000 * accel / 100) = 69 steps to full speed
 *   accel_lim = 400 * decel / (accel + decel) = 200; decel_val = -69, so
 *   deceleration starts at step 331.
 *   c_n = c_{n-1} - (2 c_{n-1} + rest) / (4 n + 1), remainder carried.
 * The move lasts about 0.79 s (thesis: the 400-step move ends at 0.7903 s).
 *
 * Globals: step_count (steps taken), running (1 while moving), done,
 * min_delay_used (the shortest step delay, ticks).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <math.h>
#include <stdint.h>

#include "afstepper.h"
#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define SPR 200
#define T1_FREQ 2000000
#define ALPHA (2 * 3.14159 / SPR)
#define A_T_x100 ((long)(ALPHA * T1_FREQ * 100))
#define T1_FREQ_148 ((int)((T1_FREQ * 0.676) / 100))
#define A_SQ (long)(ALPHA * 2 * 10000000000)
#define A_x20000 (int)(ALPHA * 20000)

#define MOVE_STEPS 400
#define ACCEL 10000 /* 100 rad/s^2 */
#define DECEL 10000
#define SPEED 2094  /* 20.94 rad/s = 200 rpm */

enum { STOP, ACCEL_STATE, RUN, DECEL_STATE };

static volatile uint8_t run_state;
static volatile unsigned int step_delay;
static int decel_val;
static unsigned int decel_start;
static unsigned int min_delay;
static int accel_count;

volatile unsigned int step_count;
volatile uint8_t running;
volatile uint8_t done;
volatile unsigned int min_delay_used = 0xFFFF;

static void move(signed int step, unsigned int accel, unsigned int decel, unsigned int speed)
{
    unsigned int max_s_lim, accel_lim;
    min_delay = A_T_x100 / speed;
    step_delay = (T1_FREQ_148 * sqrt(A_SQ / accel)) / 100;
    max_s_lim = (long)speed * speed / (long)(((long)A_x20000 * accel) / 100);
    if (max_s_lim == 0) max_s_lim = 1;
    accel_lim = ((long)step * decel) / (accel + decel);
    if (accel_lim == 0) accel_lim = 1;
    if (accel_lim <= max_s_lim) decel_val = accel_lim - step;
    else decel_val = -((long)max_s_lim * accel) / decel;
    if (decel_val == 0) decel_val = -1;
    decel_start = step + decel_val;
    if (step_delay <= min_delay) {
        step_delay = min_delay;
        run_state = RUN;
    } else {
        run_state = ACCEL_STATE;
    }
    accel_count = 0;
    running = 1;
    OCR1A = 10;
    TCNT1 = 0;
    TIMSK1 = _BV(OCIE1A);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11); /* CTC, clk/8 */
}

static void take_step(void)
{
    afstepper_onestep(FORWARD, DOUBLE);
    step_count++;
}

ISR(TIMER1_COMPA_vect)
{
    unsigned int new_step_delay = step_delay;
    static int last_accel_delay;
    static unsigned int rest = 0;

    OCR1A = step_delay;
    if (run_state != STOP && step_delay < min_delay_used) min_delay_used = step_delay;
    switch (run_state) {
        case STOP:
            rest = 0;
            TCCR1B = 0;
            running = 0;
            done = 1;
            break;
        case ACCEL_STATE:
            take_step();
            accel_count++;
            new_step_delay = step_delay - (((2 * (long)step_delay) + rest) / (4 * accel_count + 1));
            rest = ((2 * (long)step_delay) + rest) % (4 * accel_count + 1);
            if (step_count >= decel_start) {
                accel_count = decel_val;
                run_state = DECEL_STATE;
            } else if (new_step_delay <= min_delay) {
                last_accel_delay = new_step_delay;
                new_step_delay = min_delay;
                rest = 0;
                run_state = RUN;
            }
            break;
        case RUN:
            take_step();
            new_step_delay = min_delay;
            if (step_count >= decel_start) {
                accel_count = decel_val;
                new_step_delay = last_accel_delay;
                run_state = DECEL_STATE;
            }
            break;
        case DECEL_STATE:
            take_step();
            accel_count++;
            new_step_delay = step_delay - (((2 * (long)step_delay) + rest) / (4 * accel_count + 1));
            rest = ((2 * (long)step_delay) + rest) % (4 * accel_count + 1);
            if (accel_count >= 0) run_state = STOP;
            break;
    }
    step_delay = new_step_delay;
}

int main(void)
{
    afstepper_init();
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();
    move(MOVE_STEPS, ACCEL, DECEL, SPEED);
    for (;;) sleep_mode();
}
