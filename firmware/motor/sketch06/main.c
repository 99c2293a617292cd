/*
 * sketch06 - seed 003's sketch_06 (maximum pull-out rate) as written, with
 * AFMotor's own step timing: AF_Stepper motor(200, 2) on the Adafruit Motor
 * Shield v1, and from 50 rpm, for ever:
 *     motor.setSpeed(i); motor.step(200, FORWARD, DOUBLE); motor.release();
 * with i one higher each time. AF_Stepper::step() waits delay(uspers / 1000)
 * after each onestep() and carries the sub-millisecond remainder, adding a
 * delay(1) whenever it passes 1000 us (AFMotor.cpp, digest §3.1), so the
 * intervals are whole milliseconds plus the shield's overhead: at 200 rpm
 * (1500 us) they alternate 1 ms and 2 ms. motor_sweep is the same
 * experiment with exact timing.
 *
 * Bench instrumentation, not in the sketch: rpm = i, revolutions.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#define AFSTEPPER_ARDUINO_IO
#include "afstepper.h"
#include "arduino_runtime.h"
#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t rpm;
volatile uint16_t revolutions;

static uint16_t revsteps = 200;
static uint32_t usperstep, steppingcounter;

static void set_speed(uint16_t r)
{
    usperstep = 60000000 / ((uint32_t)revsteps * (uint32_t)r);
    steppingcounter = 0;
}

static void step(uint16_t steps, uint8_t dir, uint8_t style)
{
    uint32_t uspers = usperstep;
    if (style == INTERLEAVE) uspers /= 2;
    while (steps--) {
        afstepper_onestep(dir, style);
        delay(uspers / 1000); /* in ms */
        steppingcounter += (uspers % 1000);
        if (steppingcounter >= 1000) {
            delay(1);
            steppingcounter -= 1000;
        }
    }
}

int main(void)
{
    int i = 50;
    int j = 51;
    arduino_init();
    afstepper_init(); /* AF_Stepper motor(200, 2) */
    serial_begin();
    print_str("Stepper test!");
    println();
    for (i = 50; i < j; i++) {
        rpm = (uint16_t)i;
        set_speed((uint16_t)i);
        step(200, FORWARD, DOUBLE);
        afstepper_release();
        revolutions++;
        j = j + 1;
    }
    for (;;) {
    }
}
