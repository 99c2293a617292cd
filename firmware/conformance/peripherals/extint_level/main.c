/*
 * extint_level - INT0 in low-level mode (ISC01:00 = 00, the reset value).
 *
 * ATmega328P §13 / §13.2.1-13.2.3 (2560 §15, m32 "External Interrupts"):
 * "The low level of INT0 generates an interrupt request"; the interrupt
 * "will trigger as long as the pin is held low"; INTF0 "is always cleared
 * when INT0 is configured as a level interrupt".
 *
 * Phase 1: INT0 level mode, INT0 disabled, interrupts on. The bench drives
 *   the INT0 pin low; the firmware waits for it, then stores the flag
 *   register in `flags_while_disabled` (datasheet: INTF0 = 0) and sets PB3.
 * Phase 2: enable INT0. The naked ISR is `sbi PORTB,0 ; cbi PORTB,0 ; reti`
 *   and the main line is `rjmp .` (2 cycles), so while the pin stays low the
 *   ISR runs back to back: response + JMP + sbi + cbi + RETI + one rjmp.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t flags_while_disabled;

ISR(INT0_vect, ISR_NAKED)
{
    asm volatile("sbi %[portb], 0\n\t"
                 "cbi %[portb], 0\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB));
}

int main(void)
{
    DDRB = 0x0F;
    PORTD |= (1 << INT0_PIN); /* input with pull-up until the bench drives it */
    EXT_SENSE = 0;            /* INT0/INT1 low level */
    EXT_MASK = 0;
    sei();
    while (PIND & (1 << INT0_PIN)) {
    }
    for (volatile uint8_t i = 0; i < 10; ++i) {
    }
    flags_while_disabled = EXT_FLAGS;
    PORTB |= (1 << PB3);
    EXT_MASK = (1 << INT0);
    for (;;) {
        asm volatile("rjmp .-2\n\t");
    }
}
