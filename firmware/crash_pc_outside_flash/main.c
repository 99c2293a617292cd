/*
 * crash_pc_outside_flash - jumps into erased flash, past the end of the program.
 *
 * Toggles PB5 once, then calls through a function pointer to word address
 * 0x3000 (byte address 0x6000): inside the ATmega328P's 32 KiB flash (word
 * addresses 0x0000..0x3FFF) but far beyond this program's few hundred bytes,
 * so the PC lands in erased flash (every word 0xFFFF).
 *
 * AVR function pointers hold word addresses; ICALL/EICALL load the PC from Z
 * in words. 0xFFFF is not a defined instruction (it has the reserved bit 3
 * set in the SBRS encoding 1111 111r rrrr 0bbb); simavr 1.6 decodes it as
 * "sbrs r31, 7" and so walks 1-2 words per instruction through the erased
 * area up to the end of flash, where it stops with "CRASH" (state
 * cpu_Crashed) once PC >= 0x7FFF. Real silicon would wrap the PC to 0 instead.
 * The bench should report the first out-of-program PC, 0x6000.
 */
#include <avr/io.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define ERASED_FLASH_WORD_ADDRESS 0x3000u /* byte address 0x6000 */

int main(void)
{
    DDRB = _BV(PB5);
    PINB = _BV(PB5); /* the one start-up toggle */

    /* volatile: stops the compiler folding the constant into a direct
     * `call 0x6000`; an ICALL through Z is what a corrupted function pointer
     * would really do. */
    void (*volatile wild)(void) = (void (*)(void))ERASED_FLASH_WORD_ADDRESS;
    wild();

    for (;;) {
    }
}
