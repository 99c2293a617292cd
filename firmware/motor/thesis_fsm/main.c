/*
 * thesis_fsm - seed 003 §3.5, the "FSM demo" of the thesis's linear speed
 * controller (190 rpm, 600 steps, 30 rad/s^2), reproduced faithfully,
 * including its bug (seed 003 digest §3.3): every step delay is a float
 * number of milliseconds handed to Arduino's delay(unsigned long ms), which
 * truncates it to whole milliseconds. The acceleration delays run 18, 14, 12,
 * 10, 9, 8, 8, 7, ... ms and the last ~80 acceleration steps get delay(1):
 * about 1.1 ms per step with the shield's overhead, ~900 steps/s = ~270 rpm,
 * far above the motor's ~200 rpm pull-out speed. Deceleration restarts from
 * delay(1) after the 2 ms run phase. The bench must flag this as lost steps.
 *
 * The sketch, as printed in the thesis (page breaks mended as the digest
 * reads them: the loops of stateaccel() and statedrag() include the lines
 * after the break), on the Arduino runtime it ran on:
 *   - arduino_runtime.h: Timer0 millis/micros, delay() busy-waiting on
 *     micros() in 1000 us steps, Serial at 9600 baud, print() of floats.
 *   - AF_Stepper motor1(200, 2) on the Adafruit Motor Shield v1 (afstepper.h
 *     with Arduino-cost pin writes). setSpeed() is never called, so step()'s
 *     own delay is delay(0).
 * Input: each received byte first runs the previous state's function, so
 * sending "ARDS" runs accel (210 steps), run (180), decel (210): 600 steps.
 *
 * Bench instrumentation, not in the thesis: bench_steps counts onestep()s,
 * bench_phase is 1..3 while accel/run/decel run and 4 once "DONE!" is sent.
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

volatile uint16_t bench_steps;
volatile uint8_t bench_phase;

/* AF_Stepper::step(1, FORWARD, DOUBLE) with usperstep = 0 (no setSpeed()). */
static void motor1_step_forward_double(void)
{
    unsigned long uspers = 0;
    afstepper_onestep(FORWARD, DOUBLE);
    bench_steps++;
    delay(uspers / 1000);
}

/* --- the thesis's sketch (§3.5) ------------------------------------------ */

/* speed = 190 rpm, distance = 600 steps, accel = decel = 30 rad/s/s */
float a = 0.0314;
double f1 = 1000000;
float c;  /* minimum delay */
float c0; /* first step delay */
long y;
double x;
long int n, n1, n2;
long int n3;

typedef enum { STOP, RUN, DECEL, ACCEL } states;
states state = STOP;
unsigned int currentValue;

static void setup(void)
{
    serial_begin();
    c = (a * f1 * 100) / 1990; /* 190 rpm = 634 steps/sec = 19,9 rad/sec --> 1990 */
    y = 2 * a * 10000000;
    x = y * 1000;
    c0 = ((0.676 * 1000000) / 100) * (sqrt(x / 3000) / 100); /* acceleration = 30 r/s/s --> 3000 */
    n = (19.9 * 19.9) / (2 * a * 30 * 1);
    n1 = (600 * 30) / (60);
    print_str("c = ");
    print_float(c);
    println();
    print_str("c0= ");
    print_float(c0);
    println();
    print_str("n= ");
    print_long(n);
    println();
    print_str("n1= ");
    print_long(n1);
    if (n < n1) {
        n2 = (-n);
        n2 = n2;
        n3 = -n2;
    } else {
        n2 = -(400 - n1);
        n3 = -n2;
    }
    println();
    print_str("n2= ");
    print_long(n2);
    println();
    print_str("n3= ");
    print_long(n3);
    println();
    state = STOP;
}

static void statestop(const unsigned int value)
{
    (void)value;
    afstepper_release();
    print_str("Running...");
    println();
}

static void stateaccel(const unsigned int value)
{
    float c1, c2, del, del2;
    int ac = 1;
    (void)value;
    bench_phase = 1;
    c1 = (c0 - ((2 * c0) / (4 * ac + 1)));
    del = c1 / 1000; /* ms */
    delay(del);
    motor1_step_forward_double();
    for (int i = 1; i < n; i++) {
        ac = ac + 1;
        c2 = (c1 - ((2 * c1) / (4 * ac + 1)));
        del2 = c2 / 1000;
        delay(del2);
        motor1_step_forward_double();
        c1 = c2;
    }
    afstepper_release();
}

static void staterun(const unsigned int value)
{
    float del3;
    int m = 600 - n3;
    (void)value;
    bench_phase = 2;
    for (int j = n; j < m; j++) {
        del3 = c / 1000;
        (void)del3;
        delay(2);
        motor1_step_forward_double();
    }
    afstepper_release();
}

static void statedrag(const unsigned int value)
{
    float c5, del2;
    int x_ = 600 - n3;
    (void)value;
    bench_phase = 3;
    for (int i = x_; i < 600; i++) {
        c5 = (c - ((2 * c) / ((4 * n2) + 1)));
        del2 = c5 / 1000;
        delay(del2);
        motor1_step_forward_double();
        c = c5;
        n2 = n2 + 1;
    }
    afstepper_release();
    print_str("DONE!");
    println();
    bench_phase = 4;
}

static void handlePreviousState(void)
{
    switch (state) {
        case STOP: statestop(currentValue); break;
        case ACCEL: stateaccel(currentValue); break;
        case RUN: staterun(currentValue); break;
        case DECEL: statedrag(currentValue); break;
    }
    currentValue = 0;
}

static void processIncomingByte(const uint8_t byte)
{
    handlePreviousState();
    switch (byte) {
        case 'S': state = STOP; break;
        case 'A': state = ACCEL; break;
        case 'R': state = RUN; break;
        case 'D': state = DECEL; break;
        default: state = STOP; break;
    }
}

static void loop(void)
{
    if (serial_available()) processIncomingByte(serial_read());
}

int main(void)
{
    arduino_init();
    afstepper_init(); /* AF_Stepper motor1(200, 2): a global object's constructor */
    setup();
    for (;;) loop();
}
