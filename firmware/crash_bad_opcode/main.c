/*
 * crash_bad_opcode - executes an undefined instruction word.
 *
 * Toggles PB5 once (so a test sees the firmware started), then executes the
 * word 0x0001 at the global label `bad_opcode_here` (a byte address, as
 * avr-nm prints it, and as simavr prints the PC).
 *
 * Why 0x0001: in the AVR instruction set every opcode 0000 0000 xxxx xxxx
 * other than 0x0000 (NOP) is unallocated (MOVW/MULS/MULSU/FMUL* start at
 * 0x0100). simavr 1.6's decoder (sim_core.c, avr_run_one: 0x0000 group ->
 * default -> opcode & 0xff00 == 0x0000 -> default) ends in
 * _avr_invalid_opcode(), which logs
 *   "CORE: *** <pc>: Invalid Opcode SP=<sp> O=0001"
 * at LOG_ERROR. Note that simavr then just carries on with the next word, as
 * if the opcode were a 1-cycle NOP; stopping there is the bench's job.
 *
 * After it: interrupts off and a tight self-jump at `after_bad_opcode`, so a
 * simulator that ignores the opcode ends in a known, harmless place.
 */
#include <avr/io.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

int main(void)
{
    DDRB = _BV(PB5);
    PINB = _BV(PB5); /* the one start-up toggle */

    __asm__ __volatile__(
        ".global bad_opcode_here\n"
        "bad_opcode_here:\n\t"
        ".word 0x0001\n\t"          /* reserved opcode, see header */
        "cli\n"
        ".global after_bad_opcode\n"
        "after_bad_opcode:\n\t"
        "rjmp after_bad_opcode\n"
        ::: "memory");

    __builtin_unreachable();
}
