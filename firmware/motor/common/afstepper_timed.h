/*
 * afstepper_timed.h - AF_Stepper's setSpeed() and step() (AFMotor.cpp, as
 * seed 003 quotes it, digest §3.1): a step every usperstep microseconds,
 * waited as delay(usperstep / 1000) whole milliseconds with the remainder
 * carried in steppingcounter. Include after afstepper.h and
 * arduino_runtime.h. `position` counts each step, signed (bench
 * instrumentation, not in the library).
 */
#ifndef AFSTEPPER_TIMED_H
#define AFSTEPPER_TIMED_H

#include <stdint.h>

static uint16_t revsteps = 200;
/* volatile: what setSpeed() left stays in RAM, where tests read it */
volatile uint32_t usperstep;
static uint32_t steppingcounter;

/* Not inlined: AFMotor.cpp is its own unit, so setSpeed(0) divides at run time. */
static void __attribute__((noinline, unused)) afstepper_set_speed(uint16_t rpm)
{
    usperstep = 60000000 / ((uint32_t)revsteps * (uint32_t)rpm);
    steppingcounter = 0;
}

static void __attribute__((unused)) afstepper_step(uint16_t steps, uint8_t dir, uint8_t style, volatile int32_t *position)
{
    const uint32_t uspers = usperstep;
    while (steps--) {
        afstepper_onestep(dir, style);
        *position += dir == FORWARD ? 1 : -1;
        delay(uspers / 1000);
        steppingcounter += (uspers % 1000);
        if (steppingcounter >= 1000) {
            delay(1);
            steppingcounter -= 1000;
        }
    }
}

#endif
