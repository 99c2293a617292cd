/*
 * pin_pullup_off - an input whose pull-up is switched off is no longer held
 * high.
 *
 * ATmega328P §14.2.1 (2560 §13.2.1, ATmega32 "Configuring the Pin"): "If
 * PORTxn is written logic one when the pin is configured as an input pin,
 * the pull-up resistor is activated. To switch the pull-up resistor off,
 * PORTxn has to be written logic zero or the pin has to be configured as an
 * output pin"; Table 14-1: DDxn = 0, PORTxn = 0 (or PUD = 1) is "Tri-state
 * (Hi-Z)". Nothing is attached to PB0 here, so with the pull-up off the pin
 * floats; the bench's defined level for an undriven input is 0 (docs).
 *
 * reads[] (1 = PINB0 read high):
 *   0  input, PORTB0 = 1 (pull-up on)                 -> 1
 *   1  then PORTB0 = 0 (pull-up off)                  -> 0
 *   2  output driving high, then DDRB0 = 0, PORTB0 = 0 -> 0 (no longer driven)
 *   3  input, PORTB0 = 1, then PUD = 1                -> 0 (all pull-ups off)
 *   4  then PUD = 0 again                             -> 1
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t reads[5];
volatile uint8_t done;

int main(void)
{
    DDRB &= (uint8_t)~_BV(PB0);
    PORTB |= _BV(PB0);
    reads[0] = read_pin_b(PB0);
    PORTB &= (uint8_t)~_BV(PB0);
    reads[1] = read_pin_b(PB0);
    DDRB |= _BV(PB0);
    PORTB |= _BV(PB0);
    DDRB &= (uint8_t)~_BV(PB0);
    PORTB &= (uint8_t)~_BV(PB0);
    reads[2] = read_pin_b(PB0);
    PORTB |= _BV(PB0);
    PUD_REG |= _BV(PUD);
    reads[3] = read_pin_b(PB0);
    PUD_REG &= (uint8_t)~_BV(PUD);
    reads[4] = read_pin_b(PB0);
    done = 1;
    for (;;) {
    }
}
