/*
 * motor_avr446 - the linear speed controller of Atmel AVR446 ("Linear speed
 * control of stepper motor", speed_cntr.c), as seed 003 §1.5-1.6 and §4.2
 * compute it: the SM-42BYG011-25 on the Motor Shield's stepper port 2, two
 * phases on (DOUBLE), a 400-step move at 100 rad/s^2 acceleration and
 * deceleration up to 200 rpm (20.94 rad/s, the measured pull-out speed).
 *
 * AVR446's integer algorithm (firmware/lib/fw_avr446), unchanged but for the timer clock: Timer1 runs
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
#include <stdint.h>

#include "afstepper.h"
#include "avrbench_mcu.h"
#include "fw_avr446.h"

AVRBENCH_MCU_SECTION();

#define MOVE_STEPS 400
#define ACCEL 10000 /* 100 rad/s^2 */
#define DECEL 10000
#define SPEED 2094  /* 20.94 rad/s = 200 rpm */

static fw_avr446_t ramp; /* FW_AVR446_STEPS_PER_REV 200, FW_AVR446_TIMER_HZ 2 MHz (CMakeLists.txt) */

volatile unsigned int step_count;
volatile uint8_t running;
volatile uint8_t done;
volatile unsigned int min_delay_used = 0xFFFF;

static void move(unsigned int steps, unsigned int accel, unsigned int decel, unsigned int speed)
{
    fw_avr446_plan(&ramp, steps, accel, decel, speed);
    running = 1;
    OCR1A = 10;
    TCNT1 = 0;
    TIMSK1 = _BV(OCIE1A);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11); /* CTC, clk/8 */
}

ISR(TIMER1_COMPA_vect)
{
    OCR1A = ramp.step_delay;
    if (!fw_avr446_stepping(&ramp)) {
        TCCR1B = 0;
        running = 0;
        done = 1;
        return;
    }
    if (ramp.step_delay < min_delay_used) min_delay_used = ramp.step_delay;
    afstepper_onestep(FORWARD, DOUBLE);
    step_count++;
    fw_avr446_next(&ramp);
}

int main(void)
{
    afstepper_init();
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();
    move(MOVE_STEPS, ACCEL, DECEL, SPEED);
    for (;;) sleep_mode();
}
