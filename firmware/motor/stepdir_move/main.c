/*
 * stepdir_move - a step/dir move on the CNC shield's X axis (STEP PD2, DIR
 * PD5, ENABLE PB0 active low; grbl's pin map) at 1/16 microstepping: MOVE
 * microsteps forward with AVR446's linear ramp (the integer algorithm of
 * motor_avr446, in microsteps: alpha = 2 pi / 3200), or with NO_RAMP at a
 * constant SPEED from the first step and stopping dead.
 *
 * Timer1 CTC at 2 MHz (clk/8); each compare ISR raises STEP, waits 2 us
 * (the DRV8825 needs 1.9 us high) and lowers it.
 * ACCEL and SPEED in AVR446's units: 0.01 rad/s^2 and 0.01 rad/s.
 * Globals: step_count, done.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <math.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define SPR 3200 /* 200 full steps x 16 */
#define T1_FREQ 2000000
#define ALPHA (2 * 3.14159 / SPR)
#define A_T_x100 ((long)(ALPHA * T1_FREQ * 100))
#define T1_FREQ_148 ((int)((T1_FREQ * 0.676) / 100))
#define A_SQ (long)(ALPHA * 2 * 10000000000)
#define A_x20000 (int)(ALPHA * 20000)

#ifndef MOVE
#define MOVE 6400 /* two revolutions */
#endif
#ifndef ACCEL
#define ACCEL 10000 /* 100 rad/s^2 */
#endif
#ifndef SPEED
#define SPEED 2094 /* 20.94 rad/s = 200 rpm */
#endif

enum { STOP, ACCEL_STATE, RUN, DECEL_STATE };

static volatile uint8_t run_state;
static volatile unsigned int step_delay;
static int decel_val;
static unsigned int decel_start;
static unsigned int min_delay;
static int accel_count;

volatile unsigned int step_count;
volatile uint8_t done;

static void pulse(void)
{
    PORTD |= _BV(PD2);
    __builtin_avr_delay_cycles(32); /* 2 us high */
    PORTD &= (uint8_t)~_BV(PD2);
    step_count++;
}

static void move(unsigned int step, unsigned int accel, unsigned int decel, unsigned int speed)
{
    unsigned int max_s_lim, accel_lim;
    min_delay = A_T_x100 / speed;
#ifdef NO_RAMP
    (void)accel;
    (void)decel;
    (void)max_s_lim;
    (void)accel_lim;
    step_delay = min_delay;
    decel_start = step; /* never decelerate: stop dead after the last step */
    decel_val = 0;
    run_state = RUN;
#else
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
#endif
    accel_count = 0;
    OCR1A = 10;
    TCNT1 = 0;
    TIMSK1 = _BV(OCIE1A);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11);
}

ISR(TIMER1_COMPA_vect)
{
    unsigned int new_step_delay = step_delay;
    static unsigned int last_accel_delay __attribute__((unused));
    static unsigned int rest = 0;

    OCR1A = step_delay;
    switch (run_state) {
        case STOP:
            TCCR1B = 0;
            done = 1;
            break;
        case ACCEL_STATE:
            pulse();
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
            pulse();
            new_step_delay = min_delay;
            if (step_count >= decel_start) {
#ifdef NO_RAMP
                run_state = STOP;
#else
                accel_count = decel_val;
                new_step_delay = last_accel_delay;
                run_state = DECEL_STATE;
#endif
            }
            break;
        case DECEL_STATE:
            pulse();
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
    DDRD |= _BV(PD2) | _BV(PD5);
    DDRB |= _BV(PB0);
    PORTB &= (uint8_t)~_BV(PB0); /* drivers enabled */
    PORTD |= _BV(PD5);           /* DIR forward */
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();
    __builtin_avr_delay_cycles(32000); /* 2 ms: DIR set up, driver awake (DRV8825: 1.7 ms) */
    move(MOVE, ACCEL, ACCEL, SPEED);
    for (;;) sleep_mode();
}
