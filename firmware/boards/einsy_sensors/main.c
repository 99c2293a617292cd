// The Einsy RAMBo's fan tachometer and PINDA inputs read the way
// Prusa-Firmware wires them (pins_Einsy_1_0.h with its fastio.h: the hot end
// fan EXTRUDER_0_AUTO_FAN_PIN 8 = PH5, TACH_0 79 = PE6 = INT6, the PINDA on
// Z_MIN 10 = PB4, Z_STEP 35 = PC2, Z_DIR 47 = PL2, Z_ENABLE 27 = PA5), for
// the fan and inductive_probe tests (tests/boards/test_einsy_sensors.cpp).
// The fan runs from power-up; INT6 counts its tachometer's falling edges.
// Z steps down (DIR low), 100 us apart, until the PINDA reads high, at most
// 4000 steps.
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t tach_falls;
volatile uint16_t probe_steps;
volatile uint8_t done;

ISR(INT6_vect) { ++tach_falls; }

int main(void) {
    DDRH |= (1 << PH5);
    PORTH |= (1 << PH5);                 // hot end fan on
    PORTE |= (1 << PE6);                 // TACH_0: input with pull-up (open collector)
    EICRB = (1 << ISC61);                // INT6 on the falling edge
    EIMSK = (1 << INT6);
    sei();

    DDRC |= (1 << PC2);
    DDRL |= (1 << PL2);
    DDRA |= (1 << PA5);
    PORTA &= (uint8_t)~(1 << PA5);       // Z enabled
    PORTL &= (uint8_t)~(1 << PL2);       // DIR low: down
    uint16_t steps = 0;
    while (!(PINB & (1 << PB4)) && steps < 4000) {
        PORTC |= (1 << PC2);
        _delay_us(2);
        PORTC &= (uint8_t)~(1 << PC2);
        _delay_us(100);
        ++steps;
    }
    probe_steps = steps;
    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
