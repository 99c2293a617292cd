// Reads of a whole PINB byte while PB1's net floats, for the floating-input
// finding's test (tests/wiring/test_masked_pin_reads.cpp). Default build:
// every read is masked to PB0 at once - IN then ANDI 0x01, LDS then COM and
// ANDI 0x01, IN then SBRS on bit 0 - so PB1's level is never used and is no
// finding. UNMASKED: one IN whose whole byte is stored.
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t result;
volatile uint8_t done;

int main(void) {
    uint8_t r;
#ifdef UNMASKED
    __asm__ volatile("in %0, %1" : "=r"(r) : "I"(_SFR_IO_ADDR(PINB)));
    result = r;
#else
    __asm__ volatile("in %0, %1\n\tandi %0, 0x01" : "=d"(r) : "I"(_SFR_IO_ADDR(PINB)));
    result = r;
    __asm__ volatile("lds %0, %1\n\tcom %0\n\tandi %0, 0x01" : "=d"(r) : "i"(_SFR_MEM_ADDR(PINB)));
    result = r;
    __asm__ volatile("in %0, %1\n\tsbrs %0, 0\n\tldi %0, 7" : "=d"(r) : "I"(_SFR_IO_ADDR(PINB)));
    result = r;
#endif
    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
