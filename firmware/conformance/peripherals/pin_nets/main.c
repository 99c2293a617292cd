/*
 * pin_nets - pins read what the board's nets resolve to: the MCU's pull-up
 * against board resistors, open-drain (wired-AND) sharing, PUD, and an output
 * fighting a tie. The board around it is in tests/conformance_periph/
 * test_pin_nets.cpp; the expected levels come from the datasheet's DC
 * characteristics (R_PU 20-50 kohm, V_IL max 0.3 VCC, V_IH min 0.6 VCC;
 * ATmega328P §28.2, 2560 §31.2, ATmega32 §28) and Table 14-1 (pin states).
 *
 * Board: PB0 - 1 kohm to GND; PB1 - 100 kohm to GND; PB2 - 47 kohm to GND;
 * PB3 and PB4 on one net with 4.7 kohm to VCC; PB5 tied to GND (0 ohm).
 *
 * reads[] (PINx bit):
 *   0  PB0 pull-up on: 1 kohm down wins                          -> 0
 *   1  PB1 pull-up on: 100 kohm down, 0.74 VCC > V_IH             -> 1
 *   2  PB2 pull-up on: 47 kohm down, 0.57 VCC between V_IL, V_IH -> floating, 0
 *   3  PB1 again with PUD = 1: only the 100 kohm remains          -> 0
 *   4  PB4, PB3 and PB4 both inputs without pull-up: 4.7k up      -> 1
 *   5  PB4 while PB3 is an output driving low (open-drain "on")   -> 0
 *   6  PB3 while PB4 drives low and PB3 is an input               -> 0
 *   7  PB4 after both let go again                                -> 1
 * Then PB5 becomes an output driving high into the tie: contention. Last,
 * PB2 floats again while SBI PINB,7 and SBIS PINB,7 read PINB without using
 * its bit (no finding for them).
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t reads[8];
volatile uint8_t done;

int main(void)
{
    DDRB = 0;
    PORTB = _BV(PB0) | _BV(PB1) | _BV(PB2);
    reads[0] = read_pin_b(PB0);
    reads[1] = read_pin_b(PB1);
    reads[2] = read_pin_b(PB2);
    PUD_REG |= _BV(PUD);
    reads[3] = read_pin_b(PB1);
    PUD_REG &= (uint8_t)~_BV(PUD);
    PORTB = 0;

    reads[4] = read_pin_b(PB4);
    DDRB = _BV(PB3); /* PORTB3 = 0: the open-drain idiom pulls low through DDR */
    reads[5] = read_pin_b(PB4);
    DDRB = _BV(PB4);
    reads[6] = read_pin_b(PB3);
    DDRB = 0;
    reads[7] = read_pin_b(PB4);

    PORTB = _BV(PB5);
    DDRB = _BV(PB5);

    /* PB2's net floats again (pull-up on against 47 kohm), and only
     * instructions that do not use PB2's bit read PINB: SBI toggles PB7 (a
     * read-modify-write of one bit; ignored on the ATmega32, whose PINx is
     * read-only), SBIS tests PB7 alone. No second floating-input finding. */
    PORTB = _BV(PB5) | _BV(PB2);
    asm volatile("sbi %[pinb], 7\n\t"
                 "sbis %[pinb], 7\n\t"
                 "nop\n\t" ::[pinb] "I"(_SFR_IO_ADDR(PINB)));
    done = 1;
    for (;;) {
    }
}
