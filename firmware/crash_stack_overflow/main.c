/*
 * crash_stack_overflow - unbounded recursion until the stack runs into .bss.
 *
 * ATmega328P SRAM is 0x0100..0x08FF (2 KiB); the stack starts at RAMEND =
 * 0x08FF and grows down, .data/.bss grow up from 0x0100 and end at
 * __bss_end. The 512-byte `ballast` array puts __bss_end above 0x0300, so the
 * stack pointer crosses __bss_end (corrupting .bss - the fault the bench
 * must report) after ~1.5 KiB of stack, long before SP could leave SRAM and
 * start overwriting the I/O registers below 0x0100.
 *
 * Each call keeps a 16-byte volatile frame alive across the recursive call
 * (its address is passed down), so the compiler can neither drop the frame
 * nor turn the recursion into a loop; `depth_reached` records progress.
 * PB5 is toggled once at start.
 */
#include <avr/io.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

/* Global, non-static: kept in .bss and visible to the bench. */
uint8_t ballast[512];
volatile uint16_t depth_reached;

__attribute__((noinline)) static uint8_t recurse(volatile uint8_t *caller, uint16_t depth)
{
    volatile uint8_t frame[16];
    frame[0] = (uint8_t)depth;
    frame[15] = caller[0];
    depth_reached = depth;
    /* Using the result after the call keeps this a real (non-tail) call. */
    return (uint8_t)(recurse(frame, depth + 1) + frame[15]);
}

int main(void)
{
    DDRB = _BV(PB5);
    PINB = _BV(PB5); /* the one start-up toggle */

    ballast[0] = 1; /* touch it; it lives in .bss regardless */

    volatile uint8_t root = 0;
    recurse(&root, 1);
    for (;;) {
    }
}
