/*
 * busy_poll_step - the performance workload for INT0/INT1 pins held low
 * (bench/perf, docs/PERFORMANCE.md).
 *
 * Like firmware/busy_poll (a CPU-bound polling loop reading PINB), but PD2
 * and PD3 - INT0/INT1 on the ATmega328P, the step pins of an Arduino CNC
 * shield's X/Y axes - are outputs that stay low except for a short step
 * pulse every 64 iterations, with the external interrupts left at their
 * reset configuration (low level, disabled). simavr 1.6 polls a low INT0/INT1
 * pin every cycle in that configuration.
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t pinb_sum;
volatile uint16_t steps;

int main(void)
{
    DDRD = 0xFF;
    PORTD = 0;
    uint8_t iteration = 0;
    for (;;) {
        pinb_sum += PINB;
        if ((++iteration & 63u) == 0) {
            PORTD = (1 << PD2) | (1 << PD3); /* step pulse */
            ++steps;
            PORTD = 0;
        }
    }
}
