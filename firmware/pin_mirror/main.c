/*
 * pin_mirror - copies input PB0 (UNO D8) to output PB1 (UNO D9), polled.
 *
 * Used to wire two MCUs together: whatever level arrives on PB0 reappears on
 * PB1 a few cycles later (the loop latency, see README.md). PB0 has no
 * pull-up, so an unconnected PB0 is whatever the bench drives (simavr: 0).
 */
#include <avr/io.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

int main(void)
{
    /* DDB0 = 0 input, DDB1 = 1 output. PORTB0 = 0 keeps PB0's internal
     * pull-up off ("Configuring the Pin": DDxn = 0, PORTxn = 0 -> tri-state
     * input); PORTB1 = 0 starts PB1 low. */
    PORTB = 0;
    DDRB = _BV(DDB1);

    for (;;) {
        /* Reading PINB returns the synchronised pin level (PINB0). sbis/sbi
         * and cbi on PORTB touch only bit 1. */
        if (PINB & _BV(PINB0)) {
            PORTB |= _BV(PORTB1);
        } else {
            PORTB &= (uint8_t)~_BV(PORTB1);
        }
    }
}
