/*
 * pin_toggle - writing PINx.
 *
 * ATmega328P §14.2.2 "Toggling the Pin" (2560 §13.2.2): "Writing a logic one
 * to PINxn toggles the value of PORTxn, independent on the value of DDRxn.
 * Note that the SBI instruction can be used to toggle one single bit in a
 * port." §8.5: SBI/CBI "will only operate on the specified bit".
 * ATmega32 "Port B" register description: PINB is read-only ("R"): writes
 * have no effect.
 *
 * PORTB = 0x0F (outputs). Then, storing PORTB after each:
 *   sbi PINB,4      -> after_sbi       (328P/2560: 0x1F; m32: 0x0F)
 *   cbi PINB,0      -> after_cbi       (all: unchanged)
 *   PINB = 0x81     -> after_write     (328P/2560: previous ^ 0x81; m32: unchanged)
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t after_sbi;
volatile uint8_t after_cbi;
volatile uint8_t after_write;

int main(void)
{
    DDRB = 0xFF;
    PORTB = 0x0F;
    asm volatile("sbi %[pinb], 4\n\t" ::[pinb] "I"(IO_PINB));
    after_sbi = PORTB;
    asm volatile("cbi %[pinb], 0\n\t" ::[pinb] "I"(IO_PINB));
    after_cbi = PORTB;
    PINB = 0x81;
    after_write = PORTB;
    for (;;) {
    }
}
