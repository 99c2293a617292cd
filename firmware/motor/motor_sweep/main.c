/*
 * motor_sweep - seed 003's pull-out test (sketch_06 / sketch_07 style): an
 * Arduino UNO + Adafruit Motor Shield v1 turns the SM-42BYG011-25 on stepper
 * port 2 one revolution (200 full steps) at each speed, releasing the coils
 * between revolutions (sketch_06's motor.release()), and raises the speed by
 * 1 rpm per revolution, from START_RPM up to RPM_MAX.
 *
 * Corrected where the thesis's AFMotor timing is not: AF_Stepper::step()
 * paces steps with delay() in whole milliseconds (digest §3.1), so at 200 rpm
 * its intervals alternate 1 and 2 ms. Here Timer1 (CTC, clk/8 = 2 MHz, one
 * tick = 0.5 us) paces every step at 60 s / (200 * rpm), exact to a tick:
 * OCR1A + 1 = round(600000 / rpm) ticks. The step is taken in the compare
 * ISR; main() sleeps (idle) in between.
 *
 * STYLE: DOUBLE (two-phase-on) or SINGLE (one-phase-on); START_RPM, RPM_MAX.
 * Globals for the bench: rpm (the speed of the revolution in progress),
 * revolutions (completed), steps (taken), done (RPM_MAX finished).
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
#define START_RPM 100
#endif
#ifndef RPM_MAX
#define RPM_MAX 300
#endif

volatile uint16_t rpm;
volatile uint16_t revolutions;
volatile uint32_t steps;
volatile uint8_t done;
static uint8_t steps_in_rev;

static uint16_t ticks_per_step(uint16_t r)
{
    return (uint16_t)((600000UL + r / 2) / r);
}

ISR(TIMER1_COMPA_vect)
{
    if (steps_in_rev == 200) {
        /* Revolution complete: release, next speed (sketch_06's loop). */
        afstepper_release();
        revolutions++;
        steps_in_rev = 0;
        if (rpm >= RPM_MAX) {
            TCCR1B = 0;
            done = 1;
            return;
        }
        rpm++;
        OCR1A = ticks_per_step(rpm) - 1;
    }
    afstepper_onestep(FORWARD, STYLE);
    steps_in_rev++;
    steps++;
}

int main(void)
{
    afstepper_init();
    rpm = START_RPM;
    /* The first step now, then one per compare match (AF_Stepper::step()
     * steps first, then waits). */
    afstepper_onestep(FORWARD, STYLE);
    steps_in_rev = 1;
    steps = 1;
    OCR1A = ticks_per_step(rpm) - 1;
    TCNT1 = 0;
    TIMSK1 = _BV(OCIE1A);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11); /* CTC, clk/8 */
    set_sleep_mode(SLEEP_MODE_IDLE);
    sei();
    for (;;) sleep_mode();
}
