/*
 * step_boundaries - STEP/DIR timing exactly at the A4988's minimums and one
 * cycle under them, on the CNC shield's X axis (STEP PD2, DIR PD5, enable PB0
 * active low), so the bench's check of each minimum is pinned on both sides.
 *
 * A4988 (Allegro datasheet, Figure 1): STEP high >= 1 us and low >= 1 us =
 * 16 cycles at 16 MHz; DIR setup and hold >= 200 ns = 3.2, rounded up to 4
 * cycles. Between two single-bit writes (SBI/CBI, 2 cycles each, AVR
 * Instruction Set Manual) with __builtin_avr_delay_cycles(d) between them
 * the pin holds its level d + 2 cycles (step_pattern's phase 2: 6 + 2 = 8).
 *
 * In order, each pair separated by 400 cycles of quiet:
 *  1. STEP high 16 cycles (ok), then 15 (step-high-too-short)
 *  2. STEP low 16 cycles between two pulses (ok), then 15 (step-low-too-short)
 *  3. DIR changed 4 cycles before the rising STEP edge (ok), then 3
 *     (dir-setup-violation)
 *  4. DIR changed 4 cycles after the rising STEP edge (ok), then 3
 *     (dir-hold-violation)
 */
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t done;

#define STEP_HIGH() PORTD |= _BV(PD2)
#define STEP_LOW() PORTD &= (uint8_t)~_BV(PD2)
#define DIR_TOGGLE_HIGH() PORTD |= _BV(PD5)
#define DIR_TOGGLE_LOW() PORTD &= (uint8_t)~_BV(PD5)
#define QUIET() __builtin_avr_delay_cycles(400)

int main(void) {
    DDRD |= _BV(PD2) | _BV(PD5);
    DDRB |= _BV(PB0);
    PORTB &= (uint8_t)~_BV(PB0);  // enabled
    DIR_TOGGLE_HIGH();
    QUIET();

    // 1. high time
    STEP_HIGH();
    __builtin_avr_delay_cycles(14);  // 16 cycles high
    STEP_LOW();
    QUIET();
    STEP_HIGH();
    __builtin_avr_delay_cycles(13);  // 15 cycles high
    STEP_LOW();
    QUIET();

    // 2. low time between two pulses (each 32 cycles high)
    STEP_HIGH();
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    __builtin_avr_delay_cycles(14);  // 16 cycles low
    STEP_HIGH();
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    QUIET();
    STEP_HIGH();
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    __builtin_avr_delay_cycles(13);  // 15 cycles low
    STEP_HIGH();
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    QUIET();

    // 3. DIR setup before the rising edge
    DIR_TOGGLE_LOW();
    __builtin_avr_delay_cycles(2);   // 4 cycles of setup
    STEP_HIGH();
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    QUIET();
    DIR_TOGGLE_HIGH();
    __builtin_avr_delay_cycles(1);   // 3 cycles of setup
    STEP_HIGH();
    __builtin_avr_delay_cycles(30);
    STEP_LOW();
    QUIET();

    // 4. DIR hold after the rising edge
    STEP_HIGH();
    __builtin_avr_delay_cycles(2);   // 4 cycles of hold
    DIR_TOGGLE_LOW();
    __builtin_avr_delay_cycles(26);
    STEP_LOW();
    QUIET();
    STEP_HIGH();
    __builtin_avr_delay_cycles(1);   // 3 cycles of hold
    DIR_TOGGLE_HIGH();
    __builtin_avr_delay_cycles(27);
    STEP_LOW();
    QUIET();

    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
