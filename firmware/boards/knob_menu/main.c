// A two-line "menu" on the Einsy RAMBo's 20x4 LCD driven by its knob, for the
// rotary_knob part's tests (tests/boards/test_rotary_knob.cpp and the
// scenario einsy_knob_menu): the knob's contacts BTN_EN2 14 = PJ1 (A, leading
// clockwise, see bench/boards/einsy-rambo.yaml) and BTN_EN1 72 = PJ2 (B) and its button BTN_ENC 9 = PH6 (Prusa-Firmware pins_Einsy_1_0.h
// with fastio.h) close to GND and are read with the pull-ups on, every
// 100 us, as quadrature: 4 transitions a detent (Prusa's
// ENCODER_PULSES_PER_STEP). Line 1 shows "Item <detents>", line 2
// "Clicks <presses>". The LCD: as firmware/boards/lcd_hello.
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <stdio.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile int16_t transitions;   // + clockwise
volatile int16_t detents;
volatile uint16_t clicks;
volatile uint16_t missed;       // two-step jumps (a transition missed)

static void pin(volatile uint8_t* port, uint8_t bit, uint8_t on) {
    if (on) *port |= (uint8_t)(1 << bit);
    else *port &= (uint8_t)~(1 << bit);
}
static void nibble(uint8_t n) {
    pin(&PORTF, PF5, n & 1);
    pin(&PORTG, PG4, n & 2);
    pin(&PORTH, PH7, n & 4);
    pin(&PORTG, PG3, n & 8);
    PORTF |= (1 << PF7);
    _delay_us(1);
    PORTF &= (uint8_t)~(1 << PF7);
    _delay_us(1);
}
static void send(uint8_t rs, uint8_t value) {
    pin(&PORTD, PD5, rs);
    nibble(value >> 4);
    nibble(value & 0x0F);
    _delay_us(50);
}
static void show(uint8_t address, const char* s) {
    send(0, 0x80 | address);
    for (uint8_t i = 0; i < 20; ++i) send(1, *s ? (uint8_t)*s++ : ' ');
}
static void lcd_init(void) {
    DDRD |= (1 << PD5);
    DDRF |= (1 << PF7) | (1 << PF5);
    DDRG |= (1 << PG4) | (1 << PG3);
    DDRH |= (1 << PH7);
    _delay_ms(50);
    nibble(0x3);
    _delay_ms(5);
    nibble(0x3);
    _delay_us(150);
    nibble(0x3);
    _delay_us(50);
    nibble(0x2);
    _delay_us(50);
    send(0, 0x28);
    send(0, 0x08);
    send(0, 0x01);
    _delay_ms(2);
    send(0, 0x06);
    send(0, 0x0C);
}

// The knob's state as a position in the cycle 00 -> A -> A+B -> B (closed = 1).
static uint8_t knob_phase(void) {
    const uint8_t a = !(PINJ & (1 << PJ1)), b = !(PINJ & (1 << PJ2));
    static const uint8_t phase_of[4] = {0, 1, 3, 2};  // index: a | b << 1
    return phase_of[a | (b << 1)];
}

int main(void) {
    PORTJ |= (1 << PJ2) | (1 << PJ1) | (1 << PJ0);  // pull-ups on the contacts and the SD detect (same port)
    PORTH |= (1 << PH6);                // and on the button
    lcd_init();
    char line[21];
    int16_t shown_detents = -32768;
    uint16_t shown_clicks = 0xFFFF;
    uint8_t phase = knob_phase();
    uint8_t button_was = 0;
    for (;;) {
        const uint8_t now = knob_phase();
        const uint8_t step = (uint8_t)((now - phase) & 3);
        if (step == 1) ++transitions;
        if (step == 3) --transitions;
        if (step == 2) ++missed;
        phase = now;
        detents = transitions / 4;
        const uint8_t button = !(PINH & (1 << PH6));
        if (button && !button_was) ++clicks;
        button_was = button;
        if (detents != shown_detents || clicks != shown_clicks) {
            shown_detents = detents;
            shown_clicks = clicks;
            snprintf(line, sizeof line, "Item %d", detents);
            show(0x00, line);
            snprintf(line, sizeof line, "Clicks %u", clicks);
            show(0x40, line);
        }
        _delay_us(100);
    }
}
