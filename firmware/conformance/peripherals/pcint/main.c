/*
 * pcint - pin change interrupt 0 (PCINT7:0 = PB7:0 on the 328P and the 2560).
 *
 * ATmega328P §13 and §13.2.4-13.2.8 (2560 §15.2.5-15.2.8): "The pin change
 * interrupt PCI0 will trigger if any enabled PCINT7:0 pin toggles"; PCMSK0
 * selects the pins; "the interrupts will trigger even if the ... PCINT23...0
 * pins are configured as outputs"; PCIF0 "is cleared when the interrupt
 * routine is executed. Alternatively, the flag can be cleared by writing a
 * logical one to it." §7.7: a flag set while the interrupt is disabled is
 * remembered until it is enabled.
 *
 * PB0 and PB1 are inputs (the bench drives them), PB2 an output, PB4..PB7
 * outputs used as markers. PCMSK0 = PB0 | PB2.
 *  1. PCICR = 0. Marker PB4. The bench toggles PB0 once: PCIF0 set. The
 *     firmware waits for it, writes a one to PCIF0 and stores PCIFR in
 *     `flag_after_clear` (datasheet: 0).
 *  2. Marker PB5. The bench toggles PB0 again (flag set), then PB1 (masked).
 *     The firmware waits for PB1 to change, enables PCICR: the ISR runs once
 *     for the remembered flag -> count_after_enable = 1.
 *  3. Marker PB6. The bench toggles PB1 4 times (masked: no interrupt) and
 *     PB0 4 times (4 interrupts), each toggle far apart; then the firmware
 *     toggles its output PB2 twice (2 interrupts). Marker PB7 at the end.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t flag_after_clear;
volatile uint8_t count;
volatile uint8_t count_after_enable;
volatile uint8_t count_inputs;
volatile uint8_t count_outputs;

ISR(PCINT0_vect)
{
    ++count;
}

int main(void)
{
    DDRB = 0xF4; /* PB2, PB4..PB7 outputs */
    PORTB = 0;
    PCICR = 0;
    PCMSK0 = (1 << PCINT0) | (1 << PCINT2);
    PCIFR = (1 << PCIF0);
    sei();

    /* 1 */
    PORTB |= (1 << PB4);
    while (!(PCIFR & (1 << PCIF0))) {
    }
    PCIFR = (1 << PCIF0);
    flag_after_clear = PCIFR;

    /* 2 */
    PORTB |= (1 << PB5);
    uint8_t pb1 = PINB & (1 << PB1);
    while ((PINB & (1 << PB1)) == pb1) {
    }
    PCICR = (1 << PCIE0);
    for (volatile uint8_t i = 0; i < 10; ++i) {
    }
    count_after_enable = count;

    /* 3: the bench waits 2000 cycles between toggles and 20000 at the end */
    count = 0;
    PORTB |= (1 << PB6);
    for (volatile uint16_t i = 0; i < 4000; ++i) {
    }
    count_inputs = count;
    PORTB |= (1 << PB2);
    for (volatile uint8_t i = 0; i < 10; ++i) {
    }
    PORTB &= (uint8_t) ~(1 << PB2);
    for (volatile uint8_t i = 0; i < 10; ++i) {
    }
    count_outputs = (uint8_t)(count - count_inputs);
    PORTB |= (1 << PB7);
    for (;;) {
    }
}
