/*
 * step_pattern - a fixed STEP/DIR/ENABLE sequence on the CNC shield's X axis
 * (STEP PD2, DIR PD5, enable PB0 active low), with deliberate timing faults,
 * so the bench's A4988 model can be checked against known numbers.
 *
 * Timing uses __builtin_avr_delay_cycles (exact) between single SBI/CBI
 * instructions (2 cycles each, AVR Instruction Set Manual). The A4988 needs
 * STEP high >= 1 us and low >= 1 us (16 cycles at 16 MHz) and DIR setup/hold
 * >= 200 ns (4 cycles, rounded up) around the rising STEP edge.
 *
 * Phases (the global `phase` tells the test where the firmware is):
 *  1. enable, DIR high, 100 good steps: high 32 cycles, low 320 cycles
 *  2. one pulse only 8 cycles high                       -> step-high-too-short
 *  3. DIR low, STEP rising 2 cycles later                 -> dir-setup-violation
 *  4. 50 good steps with DIR low
 *  5. disable (PB0 high), 30 steps                        -> ignored by the driver
 *  6. enable, DIR high, one step, DIR low 2 cycles after
 *     the rising edge                                     -> dir-hold-violation
 *  7. two steps 36 cycles apart (high 32, low 4 cycles)  -> step-low-too-short;
 *     16 MHz / 36 = 444 kHz is within the A4988's 500 kHz but above the
 *     DRV8825's 250 kHz                                   -> step-rate-too-high there
 * Net motion with DIR high counted +: +100 +1 (phase 2) -1 (3) -50 (4)
 *  +1 (6) -2 (7, DIR low after phase 6) = +49 steps; 153 + 2 = 155 steps
 *  taken while enabled, 30 ignored.
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t phase;

#define STEP_HIGH() PORTD |= _BV(PD2)
#define STEP_LOW() PORTD &= (uint8_t)~_BV(PD2)
#define DIR_HIGH() PORTD |= _BV(PD5)
#define DIR_LOW() PORTD &= (uint8_t)~_BV(PD5)

static void good_steps(uint8_t n)
{
    while (n--) {
        STEP_HIGH();
        __builtin_avr_delay_cycles(30); /* + the CBI's 2 cycles = 32 cycles high */
        STEP_LOW();
        __builtin_avr_delay_cycles(300); /* >= 320 cycles low with the loop */
    }
}

int main(void)
{
    DDRD = _BV(PD2) | _BV(PD5);
    DDRB = _BV(PB0);
    PORTB = 0; /* enable (active low) */
    DIR_HIGH();
    __builtin_avr_delay_cycles(1600); /* 100 us before the first step */

    phase = 1;
    good_steps(100);

    phase = 2;
    STEP_HIGH();
    __builtin_avr_delay_cycles(6); /* + CBI = 8 cycles high: 0.5 us < 1 us */
    STEP_LOW();
    __builtin_avr_delay_cycles(320);

    phase = 3;
    DIR_LOW();
    STEP_HIGH(); /* 2 cycles after the DIR edge: 125 ns < 200 ns */
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    __builtin_avr_delay_cycles(320);

    phase = 4;
    good_steps(50);

    phase = 5;
    PORTB = _BV(PB0); /* disable */
    __builtin_avr_delay_cycles(320);
    good_steps(30);
    PORTB = 0; /* enable */
    __builtin_avr_delay_cycles(320);

    phase = 6;
    DIR_HIGH();
    __builtin_avr_delay_cycles(320);
    STEP_HIGH();
    DIR_LOW(); /* 2 cycles after the rising edge: 125 ns < 200 ns hold */
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    __builtin_avr_delay_cycles(320);

    phase = 7;
    STEP_HIGH();
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    __builtin_avr_delay_cycles(2); /* + SBI = 4 cycles low: 0.25 us < 1 us */
    STEP_HIGH();
    __builtin_avr_delay_cycles(30);
    STEP_LOW();

    phase = 8;
    for (;;) {
    }
}
