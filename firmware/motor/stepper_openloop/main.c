/*
 * stepper_openloop - seed 003's open-loop stepper control (Fioretos 2015)
 * on an Arduino UNO + Adafruit Motor Shield v1, the SM-42BYG011-25 on
 * stepper port 2 (bench/boards/motor-shield-v1-seed003.yaml).
 *
 * Serial, 9600 baud (UBRR0 = 207 with U2X, as the Arduino core sets it),
 * the thesis' sketch_11 protocol: a letter starts a field, digits build its
 * value, any non-digit ends it (so "S450A300D800S" sets all three):
 *   S<n>  maximum speed, steps/s        -> "MAXSPEED = <n>"
 *   A<n>  acceleration, steps/s^2       -> "ACCEL = <n>"
 *   D<n>  move to position n (absolute, as AccelStepper's moveTo)
 *                                        -> "DIST = <n>", then the move
 * and, beyond the thesis, B<n>: the deceleration alone, steps/s^2 (A sets
 * both; §4.2's timed move decelerates harder than it accelerates)
 *                                        -> "DECEL = <n>",
 * and M<n>: the step style 1 SINGLE (one phase on),
 * 2 DOUBLE (two phases on, the default), 3 INTERLEAVE (half steps),
 * 4 MICROSTEP (16 per full step, PWM on the bridge enables) -> "STYLE = <n>".
 * A move needs S and A first ("ERROR: set S and A first"). "DONE <pos>"
 * follows every move.
 *
 * The move: AVR446's linear ramp (firmware/lib/fw_avr446, alpha = 0.0314
 * as seed 003 §4.2 rounds it) from the Timer1 compare ISR, CTC at clk/8
 * (2 MHz). Speeds convert to AVR446's 0.01 rad/s as steps/s * alpha * 100.
 *
 * THESIS_DELAYS builds the thesis' way of timing the same ramp (§3.5,
 * digest §3.3): the main loop steps and then waits delay(c / 1000), a whole
 * number of milliseconds, so every delay is truncated (c0 = 16.94 ms waits
 * 16 ms; the last acceleration steps wait 1 ms, ~1000 steps/s, above the
 * motor's 667 steps/s pull-out).
 *
 * Globals for tests: position (steps, signed), moves_done, ramp_state.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>
#include <util/delay.h>

#include "afstepper.h"
#include "avrbench_mcu.h"
#include "fw_avr446.h"
#include "fw_uart.h"

AVRBENCH_MCU_SECTION();

static fw_avr446_t ramp;
static volatile uint8_t moving;
static uint8_t style = DOUBLE;
static int8_t direction = 1;
static uint16_t max_speed, accel, decel; /* steps/s, steps/s^2 */

volatile int32_t position;
volatile uint16_t moves_done;

static void step_once(void)
{
    const uint8_t dir = direction > 0 ? FORWARD : BACKWARD;
    if (style == MICROSTEP) afstepper_microstep(dir);
    else afstepper_onestep(dir, style);
    position += direction;
}

/* steps/s (or steps/s^2) -> AVR446's 0.01 rad/s (0.01 rad/s^2): * 0.0314 * 100. */
static unsigned int to_avr446(uint16_t per_s) { return (unsigned int)(((uint32_t)per_s * 314u) / 100u); }

#ifndef THESIS_DELAYS
ISR(TIMER1_COMPA_vect)
{
    OCR1A = ramp.step_delay;
    if (!fw_avr446_stepping(&ramp)) {
        TCCR1B = 0;
        moving = 0;
        return;
    }
    step_once();
    fw_avr446_next(&ramp);
}

static void run_move(unsigned int steps)
{
    fw_avr446_plan(&ramp, steps, to_avr446(accel), to_avr446(decel), to_avr446(max_speed));
    moving = 1;
    OCR1A = 10;
    TCNT1 = 0;
    TIMSK1 = _BV(OCIE1A);
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11); /* CTC, clk/8 = 2 MHz */
    while (moving) fw_uart_idle();
}
#else
static void delay_whole_ms(unsigned int ms)
{
    while (ms--) _delay_ms(1);
}

static void run_move(unsigned int steps)
{
    fw_avr446_plan(&ramp, steps, to_avr446(accel), to_avr446(decel), to_avr446(max_speed));
    while (fw_avr446_stepping(&ramp)) {
        step_once();
        const unsigned int c_ticks = ramp.step_delay;
        fw_avr446_next(&ramp);
        /* delay(c / 1000) with c in us: ticks are 0.5 us, and the division truncates. */
        delay_whole_ms(c_ticks / 2000u);
    }
}
#endif

static void put_field(const char *name, uint32_t value)
{
    fw_uart_puts(name);
    fw_uart_puts(" = ");
    fw_uart_put_u32(value);
    fw_uart_puts("\r\n");
}

static void move_to(uint16_t target)
{
    if (max_speed == 0 || accel == 0 || decel == 0) {
        fw_uart_puts("ERROR: set S and A first\r\n");
        return;
    }
    const int32_t delta = (int32_t)target - position;
    direction = delta < 0 ? -1 : 1;
    const uint32_t steps = (uint32_t)(delta < 0 ? -delta : delta);
    if (steps > 0) {
        afstepper_pwm(style == MICROSTEP);
        run_move((unsigned int)steps);
    }
    ++moves_done;
    fw_uart_puts("DONE ");
    fw_uart_put_i32(position);
    fw_uart_puts("\r\n");
}

/* The sketch_11 state machine: a field is handled when a non-digit ends it. */
static char field;
static uint16_t value;

static void end_field(void)
{
    switch (field) {
        case 'S':
            max_speed = value;
            put_field("MAXSPEED", value);
            break;
        case 'A':
            accel = decel = value;
            put_field("ACCEL", value);
            break;
        case 'B':
            decel = value;
            put_field("DECEL", value);
            break;
        case 'D':
            put_field("DIST", value);
            move_to(value);
            break;
        case 'M':
            if (value >= SINGLE && value <= MICROSTEP) {
                style = (uint8_t)value;
                put_field("STYLE", value);
            } else {
                fw_uart_puts("ERROR: style 1..4\r\n");
            }
            break;
        default:
            break;
    }
    value = 0;
}

static void on_byte(char c)
{
    if (c >= '0' && c <= '9') {
        value = (uint16_t)(value * 10u + (uint16_t)(c - '0'));
        return;
    }
    end_field();
    field = (c == 'S' || c == 'A' || c == 'B' || c == 'D' || c == 'M') ? c : 0;
}

int main(void)
{
    afstepper_init();
    fw_uart_init(207, 1); /* 9600 baud: UBRR0 = 207, U2X0 (Arduino core) */
    sei();
    fw_uart_puts("stepper_openloop ready\r\n");
    for (;;) {
        const int16_t c = fw_uart_getc();
        if (c < 0) fw_uart_idle();
        else on_byte((char)c);
    }
}
