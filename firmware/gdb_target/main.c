/*
 * gdb_target - a firmware to debug: a counter, a function that changes it,
 * an EEPROM byte and an I/O pin, each with a value a test can work out from
 * this source alone (tests/debug, docs/DEBUGGING.md).
 *
 *   ticks     += 3 in tick(), called once per pass of main's loop, so on the
 *               n-th call of tick() (counting from 1) ticks holds 3 * (n - 1)
 *               on entry;
 *   last_seen  copies ticks in main after each call (a read of ticks there);
 *   PB5        toggles on every pass (PINB write, ATmega328P datasheet 14.2.2);
 *   eeprom_word is 0xBEEF in the ELF's .eeprom section.
 *
 * Built with -O1 like every firmware here; tick() is noinline so a
 * breakpoint on it is hit once per pass.
 */
#include <avr/eeprom.h>
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t ticks;
volatile uint16_t last_seen;
uint16_t EEMEM eeprom_word = 0xBEEF;

__attribute__((noinline)) void tick(void) { ticks += 3; }

int main(void) {
    DDRB = _BV(PB5);
    for (;;) {
        tick();
        last_seen = ticks;
        PINB = _BV(PB5);
    }
}
