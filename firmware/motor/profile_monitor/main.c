/*
 * profile_monitor - seed 003's §3.4 profile monitor (digest §2.6 and table
 * 4.3): the speed recurrence of the AccelStepper version the thesis quotes,
 * replayed from spd0 = 30 steps/s with accel = 3000 steps/s^2, maxspd 650
 * and a 400-step move, printing each step's cumulative time and speed; then
 * runToPosition(400) on stepper 2, onestep(FORWARD, DOUBLE) per step.
 *
 * The recurrence as the digest quotes it (desiredSpeed()): the speed the
 * remaining distance allows is sqrt(2 * distanceTo * accel); while the
 * current speed is below it the next is speed + |accel / speed| (sqrt(2 *
 * accel) from standstill), else speed - |accel / speed|; clamped to maxspd.
 * A step's interval is 1000 / speed ms (setSpeed(): _stepInterval =
 * abs(1000.0 / _speed), "// ms"). The monitor prints "n t_ms speed" after
 * each step n, with Arduino's Print::print(float) (two decimals), for the
 * ramp (n = 1..MONITOR_STEPS).
 *
 * Running, as AccelStepper 1.1 (2010, the millisecond version the digest
 * means: "an old version with intervals in ms") does it: _stepInterval is an
 * unsigned long, so 1000 / speed is truncated to whole milliseconds; a step
 * is taken once millis() > the last step's millis() + _stepInterval, and the
 * last step's time starts at 0. The real pulses come about one whole
 * millisecond later than the truncated interval, not at the times printed.
 *
 * Bench instrumentation, not in the sketch: position, moves_done.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <math.h>
#include <stdint.h>

#define AFSTEPPER_ARDUINO_IO
#include "afstepper.h"
#include "arduino_runtime.h"
#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define SPEED0 30.0f     /* steps/s */
#define ACCEL 3000.0f    /* steps/s^2 */
#define MAX_SPEED 650.0f /* steps/s */
#define DISTANCE 400
#define MONITOR_STEPS 70

volatile int32_t position;
volatile uint16_t moves_done;

/* desiredSpeed(), `distance_to` steps from the target, at `speed` now. */
static float desired_speed(float speed, long distance_to)
{
    const float required = sqrtf(2.0f * (float)distance_to * ACCEL);
    float next;
    if (required > speed) {
        next = speed == 0.0f ? sqrtf(2.0f * ACCEL) : speed + fabsf(ACCEL / speed);
    } else {
        next = speed - fabsf(ACCEL / speed);
    }
    return next > MAX_SPEED ? MAX_SPEED : next;
}

int main(void)
{
    arduino_init();
    afstepper_init();
    serial_begin();
    float speed = SPEED0, t_ms = 0.0f;
    for (long n = 1; n <= MONITOR_STEPS; ++n) {
        speed = desired_speed(speed, DISTANCE - n + 1);
        t_ms += 1000.0f / speed;
        print_long(n);
        serial_write(' ');
        print_float(t_ms);
        serial_write(' ');
        print_float(speed);
        println();
    }
    /* runToPosition(400): the same recurrence, one step per whole-ms interval. */
    speed = SPEED0;
    unsigned long last_step_ms = 0;
    for (long n = 1; n <= DISTANCE; ++n) {
        speed = desired_speed(speed, DISTANCE - n + 1);
        const unsigned long interval_ms = (unsigned long)fabsf(1000.0f / speed);
        unsigned long now;
        while (!((now = millis()) > last_step_ms + interval_ms)) {
        }
        last_step_ms = now;
        afstepper_onestep(FORWARD, DOUBLE);
        ++position;
    }
    moves_done = 1;
    for (;;) {
    }
}
