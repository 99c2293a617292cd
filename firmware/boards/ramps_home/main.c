/*
 * ramps_home - homes X and Y of a RAMPS 1.4 board the way Marlin 1.1/2.x
 * reads its min endstops, and records what the inputs read.
 *
 * Marlin's defaults (Configuration.h): ENDSTOPPULLUPS (the MCU's pull-ups on
 * every endstop input) and X/Y/Z_MIN_ENDSTOP_INVERTING false: an input that
 * reads HIGH is a triggered endstop. That is a normally-closed switch to GND
 * (closed at rest: LOW; opened by the carriage: HIGH through the pull-up), or
 * an optical endstop whose output goes high when blocked. Built with
 * ENDSTOP_INVERTING (Marlin's *_ENDSTOP_INVERTING true), LOW is triggered: a
 * normally-open switch to GND.
 *
 * RAMPS 1.4 pins (pins_RAMPS.h): X STEP PF0, DIR PF1, EN PD7 (low = on), MIN
 * PE5; Y STEP PF6, DIR PF7, EN PF2, MIN PJ1; Z MIN PD3. DIR low moves towards
 * min. Steps: STEP high 32 cycles (A4988 >= 1 us = 16), then low 1568 cycles:
 * 10 kHz, 125 mm/s at 80 steps/mm.
 *
 * Recorded: rest_triggered (bit 0 X, 1 Y, 2 Z: what Marlin's M119 would say
 * before homing), x_steps / y_steps (steps towards min until triggered, at
 * most 20000), done = 1.
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#if defined(ENDSTOP_INVERTING)
#define TRIGGERED(pinreg, bit) (((pinreg) & _BV(bit)) == 0)
#else
#define TRIGGERED(pinreg, bit) (((pinreg) & _BV(bit)) != 0)
#endif

#define MAX_STEPS 20000u

volatile uint8_t rest_triggered;
volatile uint16_t x_steps;
volatile uint16_t y_steps;
volatile uint8_t done;

static void step_x(void)
{
    PORTF |= _BV(PF0);
    __builtin_avr_delay_cycles(32);
    PORTF &= (uint8_t)~_BV(PF0);
    __builtin_avr_delay_cycles(1568);
}

static void step_y(void)
{
    PORTF |= _BV(PF6);
    __builtin_avr_delay_cycles(32);
    PORTF &= (uint8_t)~_BV(PF6);
    __builtin_avr_delay_cycles(1568);
}

int main(void)
{
    DDRF = _BV(PF0) | _BV(PF1) | _BV(PF6) | _BV(PF7) | _BV(PF2);
    DDRD = _BV(PD7);
    PORTF = 0; /* DIR low (towards min), Y enabled */
    PORTD = _BV(PD3); /* X enabled (PD7 low); Z MIN pull-up */
    PORTE = _BV(PE5); /* X MIN pull-up */
    PORTJ = _BV(PJ1); /* Y MIN pull-up */
    __builtin_avr_delay_cycles(1600); /* inputs settled */

    rest_triggered = (uint8_t)((TRIGGERED(PINE, PE5) ? 1 : 0) | (TRIGGERED(PINJ, PJ1) ? 2 : 0) |
                               (TRIGGERED(PIND, PD3) ? 4 : 0));
    while (!TRIGGERED(PINE, PE5) && x_steps < MAX_STEPS) {
        step_x();
        ++x_steps;
    }
    while (!TRIGGERED(PINJ, PJ1) && y_steps < MAX_STEPS) {
        step_y();
        ++y_steps;
    }
    done = 1;
    for (;;) {
    }
}
