// A 20x4 HD44780 LCD on the Einsy RAMBo's display connector, driven in
// 4-bit mode the way the HD44780U datasheet's "Initializing by Instruction"
// (Figure 24) describes, for the hd44780 part's tests
// (tests/boards/test_hd44780.cpp). Pins (Prusa-Firmware pins_Einsy_1_0.h with
// fastio.h): LCD_PINS_RS 82 = PD5, LCD_PINS_ENABLE 61 = PF7, D4 59 = PF5,
// D5 70 = PG4, D6 85 = PH7, D7 71 = PG3; R/W is tied low on the board.
//
// Shows "Hello, Einsy" on line 1 and "Temp 215<degree>C" on line 4.
// TOO_EARLY: the entry mode set follows the clear display at once (the
// clear needs 1.52 ms).
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t done;

static void pin(volatile uint8_t* port, uint8_t bit, uint8_t on) {
    if (on) *port |= (uint8_t)(1 << bit);
    else *port &= (uint8_t)~(1 << bit);
}

static void nibble(uint8_t n) {
    pin(&PORTF, PF5, n & 1);
    pin(&PORTG, PG4, n & 2);
    pin(&PORTH, PH7, n & 4);
    pin(&PORTG, PG3, n & 8);
    PORTF |= (1 << PF7);                  // E high >= 230 ns (PW_EH)
    _delay_us(1);
    PORTF &= (uint8_t)~(1 << PF7);        // latched on the falling edge
    _delay_us(1);
}

static void send(uint8_t rs, uint8_t value) {
    pin(&PORTD, PD5, rs);
    nibble(value >> 4);
    nibble(value & 0x0F);
    _delay_us(50);                        // 37 us execution time (Table 6)
}

static void text(const char* s) {
    while (*s) send(1, (uint8_t)*s++);
}

int main(void) {
    DDRD |= (1 << PD5);
    DDRF |= (1 << PF7) | (1 << PF5);
    DDRG |= (1 << PG4) | (1 << PG3);
    DDRH |= (1 << PH7);
    _delay_ms(50);                        // > 15 ms after power-up
    nibble(0x3);                          // function set, 8 bits
    _delay_ms(5);                         // > 4.1 ms
    nibble(0x3);
    _delay_us(150);                       // > 100 us
    nibble(0x3);
    _delay_us(50);
    nibble(0x2);                          // function set: 4 bits
    _delay_us(50);
    send(0, 0x28);                        // 4 bits, 2 lines, 5x8 dots
    send(0, 0x08);                        // display off
    send(0, 0x01);                        // clear display
#ifndef TOO_EARLY
    _delay_ms(2);                         // 1.52 ms
#endif
    send(0, 0x06);                        // entry mode: increment, no shift
    send(0, 0x0C);                        // display on, no cursor
    text("Hello, Einsy");
    send(0, 0x80 | 0x54);                 // line 4 of a 20x4: DDRAM 0x54
    text("Temp 215");
    send(1, 0xDF);                        // the A00 ROM's degree sign
    text("C");
    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
