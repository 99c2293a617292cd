/*
 * motor_start - seed 003's start/stop test: from rest, with no ramp, the
 * shield turns the SM-42BYG011-25 (stepper port 2) STEPS full steps at a
 * fixed START_RPM, stops dead on the last step and holds it for 300 ms with
 * the coils energized, then releases them.
 *
 * Timer1 (CTC, clk/8 = 2 MHz) paces the steps at 60 s / (200 * rpm): OCR1A +
 * 1 = round(600000 / rpm) ticks; the first step is taken at once (as
 * AF_Stepper::step() does). STYLE: DOUBLE or SINGLE.
 * Globals: steps (taken), done (1 once the coils are released).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "afstepper.h"
#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#ifndef STYLE
#define STYLE DOUBLE
#endif
#ifndef START_RPM
#define START_RPM 145
#endif
#ifndef STEPS
#define STEPS 200
#endif
#define HOLD_TICKS 30 /* 300 ms in 10 ms Timer1 periods after the move */

volatile uint16_t steps;
volatile uint8_t done;
static uint8_t hold;

ISR(TIMER1_COMPA_vect)
{
    if (steps < STEPS) {
        afstepper_onestep(FORWARD, STYLE);
        if (++steps == STEPS) OCR1A = 20000 - 1; /* then 10 ms ticks */
        return;
    }
    if (++hold == HOLD_TICKS) {
        afstepper_release();
        TCCR1B = 0;
        done = 1;
    }
}

int main(void)
{
    afstepper_init();
    afstepper_onestep(FORWARD, STYLE);
    steps = 1;
    OCR1A = (uint16_t)((600000UL + START_RPM / 2) / START_RPM) - 1;
    TCNT1 = 0;
    TIMSK1 = _BV(OCIE1A);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11); /* CTC, clk/8 */
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();
    for (;;) sleep_mode();
}
