/*
 * extint_edges - INT0/INT1 edge modes, the INTF flags and enabling with a
 * flag already set.
 *
 * ATmega328P §13.2.1 Table 13-2 (2560 §15.2.1, m32 MCUCR ISC bits):
 * ISCn1:0 = 01 any logical change, 10 falling edge, 11 rising edge.
 * §13.2.3: "the flag is cleared when the interrupt routine is executed.
 * Alternatively, the flag can be cleared by writing a logical one to it."
 * §7.7: a flag set while its interrupt is disabled "will be set and
 * remembered until the interrupt is enabled, or the flag is cleared by software".
 *
 * Each step sets a PORTB marker and waits; the bench then makes the edges.
 *  1. INT0 falling, disabled. Marker PB0. The bench drives INT0 low: the
 *     firmware waits for INTF0, stores 1 in `flag_set`, writes a one to INTF0
 *     and stores the flag register in `flag_after_clear` (datasheet: INTF0 = 0).
 *  2. Marker PB1. The bench drives INT0 high and low again (a new falling
 *     edge, INTF0 set). The firmware waits for the pin low, then enables INT0
 *     with interrupts on: the ISR must run (`int0_count` = 1).
 *  3. INT1 any change: marker PB2, the bench toggles INT1 4 times -> 4 ISRs.
 *  4. INT1 falling: marker PB3, 4 toggles -> 2 ISRs.
 *  5. INT1 rising: marker PB4, 4 toggles -> 2 ISRs.
 * The INT1 ISR counts into int1_count[step]; the firmware moves on when the
 * bench sets INT0 high and then low (it waits for that).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t flag_set;
volatile uint8_t flag_after_clear;
volatile uint8_t int0_count;
volatile uint8_t int1_step;
volatile uint8_t int1_count[3];

ISR(INT0_vect)
{
    ++int0_count;
    EXT_MASK &= (uint8_t) ~(1 << INT0);
}

ISR(INT1_vect)
{
    ++int1_count[int1_step];
}

static void wait_int0(uint8_t level)
{
    while (((PIND >> INT0_PIN) & 1) != level) {
    }
}

int main(void)
{
    DDRB = 0xFF;
    PORTB = 0;
    PORTD |= (1 << INT0_PIN) | (1 << INT1_PIN); /* pull-ups */
    EXT_MASK = 0;
    EXT_SENSE = (1 << ISC01); /* INT0 falling, INT1 low level (disabled) */
    EXT_FLAGS = (1 << INTF0) | (1 << INTF1);
    sei();

    /* 1 */
    PORTB |= (1 << PB0);
    while (!(EXT_FLAGS & (1 << INTF0))) {
    }
    flag_set = 1;
    EXT_FLAGS = (1 << INTF0);
    flag_after_clear = EXT_FLAGS;

    /* 2 */
    PORTB |= (1 << PB1);
    wait_int0(1);
    wait_int0(0);
    EXT_MASK = (1 << INT0);
    for (volatile uint8_t i = 0; i < 10; ++i) {
    }

    /* 3..5 */
    static const uint8_t modes[3] = {(1 << ISC10), (1 << ISC11), (1 << ISC11) | (1 << ISC10)};
    for (uint8_t step = 0; step < 3; ++step) {
        EXT_MASK = 0;
        int1_step = step;
        EXT_SENSE = (uint8_t)((1 << ISC01) | modes[step]);
        EXT_FLAGS = (1 << INTF1);
        EXT_MASK = (1 << INT1);
        PORTB |= (uint8_t)(1 << (PB2 + step));
        wait_int0(1);
        wait_int0(0);
    }
    EXT_MASK = 0;
    PORTB |= (1 << PB5);
    for (;;) {
    }
}
