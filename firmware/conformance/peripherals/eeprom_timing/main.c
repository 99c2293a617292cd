/*
 * eeprom_timing - EEPROM read/write timing and the EE_READY interrupt.
 *
 * ATmega328P §8.4, §8.6.3 (2560 §8.3, §8.6.3; m32 "EEPROM Data Memory"):
 *  - "When the EEPROM is read, the CPU is halted for four cycles before the
 *    next instruction is executed"; "When EEPE has been written, the CPU is
 *    halted for two cycles";
 *  - EEPE stays one until the write is done: 3.4 ms for erase and write
 *    (EEPM = 00), 1.8 ms erase only (01), 1.8 ms write only (10) (328P Table
 *    8-2, 2560 Table 8-1); m32 (no EEPM): 8448 cycles of the 1 MHz calibrated
 *    RC oscillator (Table 1);
 *  - "The EEPROM Ready interrupt generates a constant interrupt when EEPE is
 *    cleared" (EERIE set).
 *
 *  1. `sbi PORTB,0 ; sbi EECR,EERE ; sbi PORTB,1` reads address 5 (0x5A from
 *     the .eeprom section) into `read_value`.
 *  2. EEDR = 0xA5, EEAR = 6: `sbi PORTB,2 ; sbi EECR,EEMPE ; sbi EECR,EEPE ;
 *     sbi PORTB,3`, then poll EEPE (sbic/rjmp) and `sbi PORTB,4`.
 *  3. (328P/2560) EEPM = 10 (write only), EEDR = 0x0F at address 5 (0x5A):
 *     result 0x5A & 0x0F = 0x0A; EEPM = 01 (erase only) at address 7: 0xFF.
 *  4. EERIE with no write in progress: the ISR runs at once (count_idle).
 *  5. Write with EERIE set, main asleep (Idle): the naked EE_READY ISR sets
 *     PB5 and clears EERIE. Marker PB6 just before the write sequence.
 */
#include <avr/eeprom.h>
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

#if defined(__AVR_ATmega32__)
#define EEMPE EEMWE
#define EEPE EEWE
#define EE_READY_VECT EE_RDY_vect
#else
#define EE_READY_VECT EE_READY_vect
#endif
#define IO_EECR _SFR_IO_ADDR(EECR)

uint8_t ee_data[8] EEMEM = {0, 1, 2, 3, 4, 0x5A, 6, 7};

volatile uint8_t read_value;
volatile uint8_t value6, value5, value7;
volatile uint8_t count_idle;
volatile uint8_t phase;

ISR(EE_READY_VECT, ISR_NAKED)
{
    asm volatile("sbi %[portb], 5\n\t"
                 "cbi %[eecr], %[eerie]\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB),
                 [eecr] "I"(IO_EECR), [eerie] "I"(EERIE));
}

static uint8_t read_at(uint16_t a)
{
    while (EECR & (1 << EEPE)) {
    }
    EEAR = a;
    EECR |= (1 << EERE);
    return EEDR;
}

__attribute__((unused)) static void write_at(uint16_t a, uint8_t v)
{
    while (EECR & (1 << EEPE)) {
    }
    EEAR = a;
    EEDR = v;
    asm volatile("sbi %[eecr], %[mpe]\n\t"
                 "sbi %[eecr], %[pe]\n\t" ::[eecr] "I"(IO_EECR),
                 [mpe] "I"(EEMPE), [pe] "I"(EEPE));
}

int main(void)
{
    DDRB = 0x7F;
    PORTB = 0;
    (void)ee_data;

    /* 1 */
    EEAR = 5;
    asm volatile("sbi %[portb], 0\n\t"
                 "sbi %[eecr], %[re]\n\t"
                 "sbi %[portb], 1\n\t" ::[portb] "I"(IO_PORTB),
                 [eecr] "I"(IO_EECR), [re] "I"(EERE));
    read_value = EEDR;

    /* 2 */
    EEAR = 6;
    EEDR = 0xA5;
    asm volatile("sbi %[portb], 2\n\t"
                 "sbi %[eecr], %[mpe]\n\t"
                 "sbi %[eecr], %[pe]\n\t"
                 "sbi %[portb], 3\n\t"
                 "1: sbic %[eecr], %[pe]\n\t"
                 "rjmp 1b\n\t"
                 "sbi %[portb], 4\n\t" ::[portb] "I"(IO_PORTB),
                 [eecr] "I"(IO_EECR), [mpe] "I"(EEMPE), [pe] "I"(EEPE));
    value6 = read_at(6);

    /* 3 */
#if defined(EEPM0)
    EECR = (1 << EEPM1); /* write only */
    write_at(5, 0x0F);
    value5 = read_at(5);
    EECR = (1 << EEPM0); /* erase only */
    write_at(7, 0x00);
    value7 = read_at(7);
    EECR = 0;
#endif

    /* 4 */
    phase = 4;
    sei();
    EECR |= (1 << EERIE);
    for (volatile uint8_t i = 0; i < 5; ++i) {
    }
    count_idle = (PORTB & (1 << PB5)) ? 1 : 0;
    PORTB &= (uint8_t) ~(1 << PB5);

    /* 5 */
    phase = 5;
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();
    EEAR = 4;
    EEDR = 0x44;
    cli();
    asm volatile("sbi %[portb], 6\n\t"
                 "sbi %[eecr], %[mpe]\n\t"
                 "sbi %[eecr], %[pe]\n\t"
                 "sbi %[eecr], %[rie]\n\t"
                 "sei\n\t"
                 "sleep\n\t" ::[portb] "I"(IO_PORTB),
                 [eecr] "I"(IO_EECR), [mpe] "I"(EEMPE), [pe] "I"(EEPE), [rie] "I"(EERIE));
    for (;;) {
    }
}
