/*
 * servo_sweep - RC servo pulses from Timer1 on OC1A (PB1, UNO D9), the way
 * the CNC seed's pen servo is driven: fast PWM mode 14 (TOP = ICR1),
 * prescaler 8, so one tick is 0.5 us at 16 MHz and ICR1 = 39999 makes a
 * 20 ms frame (ATmega328P §16.9.3, Table 16-4); the pulse is OCR1A + 1
 * ticks (§16.9.3: OC1A is set at BOTTOM and cleared on the compare match
 * after OCR1A, which is double-buffered and updated at BOTTOM).
 *
 * Pulse widths, each held for the time given (the test's board gives the
 * servo a 0:1000,180:2000 table, 300 deg/s):
 *   1500 us for 0.5 s, 2000 us for 0.5 s, 1000 us for 0.5 s,
 *   3000 us for 0.2 s (outside the table: clamped, a finding), 1500 us.
 */
#include <avr/io.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

static void pulse_us(uint16_t us)
{
    OCR1A = (uint16_t)(us * 2u - 1u);
}

int main(void)
{
    DDRB = _BV(PB1);
    ICR1 = 39999;
    pulse_us(1500);
    TCCR1A = _BV(COM1A1) | _BV(WGM11);
    TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS11);
    _delay_ms(500);
    pulse_us(2000);
    _delay_ms(500);
    pulse_us(1000);
    _delay_ms(500);
    pulse_us(3000);
    _delay_ms(200);
    pulse_us(1500);
    for (;;) {
    }
}
