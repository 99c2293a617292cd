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
#include <stdint.h>

#include "avrbench_mcu.h"
#include "fw_avr446.h"

AVRBENCH_MCU_SECTION();

#ifndef MOVE
#define MOVE 6400 /* two revolutions */
#endif
#ifndef ACCEL
#define ACCEL 10000 /* 100 rad/s^2 */
#endif
#ifndef SPEED
#define SPEED 2094 /* 20.94 rad/s = 200 rpm */
#endif

static fw_avr446_t ramp; /* FW_AVR446_STEPS_PER_REV 3200 (200 full steps x 16), 2 MHz (CMakeLists.txt) */

volatile unsigned int step_count;
volatile uint8_t done;

static void pulse(void)
{
    PORTD |= _BV(PD2);
    __builtin_avr_delay_cycles(32); /* 2 us high */
    PORTD &= (uint8_t)~_BV(PD2);
    step_count++;
}

static void move(unsigned int steps, unsigned int accel, unsigned int decel, unsigned int speed)
{
#ifdef NO_RAMP
    (void)accel;
    (void)decel;
    fw_avr446_plan_constant(&ramp, steps, speed);
#else
    fw_avr446_plan(&ramp, steps, accel, decel, speed);
#endif
    OCR1A = 10;
    TCNT1 = 0;
    TIMSK1 = _BV(OCIE1A);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11);
}

ISR(TIMER1_COMPA_vect)
{
    OCR1A = ramp.step_delay;
    if (!fw_avr446_stepping(&ramp)) {
        TCCR1B = 0;
        done = 1;
        return;
    }
    pulse();
    fw_avr446_next(&ramp);
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
