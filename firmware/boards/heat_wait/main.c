/*
 * heat_wait - a RAMPS 1.4 controller waiting for its hot end to reach
 * temperature, in the shape Teacup waits (M109/M116): a 2 ms clock tick
 * interrupt, the hot end heater regulated every 100 ms from a thermistor
 * reading, the bed heater's hardware PWM left at duty 0, a status line once
 * a second, and the main loop spinning in a busy-wait delay between checks.
 * For bench/perf's fast-forward table (docs/PERFORMANCE.md); written for
 * this repository from the datasheet, no third-party code.
 *
 * Pins (RAMPS 1.4, bench/boards/ramps-1.4.yaml):
 *   D8  = PH5 = OC4C  bed heater: Timer4 8-bit fast PWM (WGM4 = 5) at clk/1,
 *                     COM4C = 10, OCR4C = 0: "a narrow spike for each MAX+1
 *                     timer clock cycle" (2560 §17.9.3), 62.5 ns every 16 us,
 *                     as Teacup leaves its bed at duty 0
 *   D10 = PB4 = OC2A  hot end heater: Timer2 fast PWM at clk/64 (976 Hz),
 *                     OCR2A = duty, high for OCR2A + 1 of 256 counts
 *   A13 = PK5 = ADC13 hot end thermistor (MUX5 = 1, MUX2:0 = 101)
 *   USART0 115200 8N1: "T:<adc> D:<duty>" once a second, "ok" when reached
 * Timer1 CTC at clk/8, OCR1A = 3999: a tick every 4000 * 8 = 32000 cycles
 * (2 ms). Control every 50 ticks: one polled conversion (ADC clock /128),
 * duty = clamp(4 * (adc - TARGET_ADC)) (the NTC's reading falls as it heats).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>
#include <util/delay_basic.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define TARGET_ADC 100u /* ~200 degC on the EPCOS 100k with 4.7 kohm to 5 V */

volatile uint16_t ticks;
volatile uint16_t last_adc;
volatile uint8_t duty;
volatile uint8_t reached;

ISR(TIMER1_COMPA_vect) { ++ticks; }

static void uart_put(char c)
{
    while (!(UCSR0A & (1 << UDRE0))) {
    }
    UDR0 = c;
}

static void uart_number(uint16_t v)
{
    char digits[5];
    uint8_t n = 0;
    do {
        digits[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v != 0);
    while (n != 0) uart_put(digits[--n]);
}

static uint16_t read_thermistor(void)
{
    ADMUX = (1 << REFS0) | (13 & 0x07);
    ADCSRB = (1 << MUX5);
    ADCSRA |= (1 << ADSC);
    while (ADCSRA & (1 << ADSC)) {
    }
    return ADC;
}

int main(void)
{
    DDRH |= (1 << PH5);
    DDRB |= (1 << PB4);
    OCR4C = 0;
    TCCR4A = (1 << COM4C1) | (1 << WGM40);
    TCCR4B = (1 << WGM42) | (1 << CS40);
    OCR2A = 0;
    TCCR2A = (1 << COM2A1) | (1 << WGM21) | (1 << WGM20);
    TCCR2B = (1 << CS22); /* clk/64 */
    OCR1A = 3999;
    TCCR1B = (1 << WGM12) | (1 << CS11);
    TIMSK1 = (1 << OCIE1A);
    ADCSRA = (1 << ADEN) | (1 << ADPS2) | (1 << ADPS1) | (1 << ADPS0);
    UCSR0A = (1 << U2X0);
    UBRR0 = 16; /* 115200 at 16 MHz with U2X0: 16e6 / (8 * 17) = 117647 baud, +2.1 % */
    UCSR0B = (1 << TXEN0);
    sei();

    uint16_t controlled_at = 0, reported_at = 0;
    for (;;) {
        cli();
        const uint16_t now = ticks;
        sei();
        if ((uint16_t)(now - controlled_at) >= 50) {
            controlled_at = now;
            const uint16_t adc = read_thermistor();
            last_adc = adc;
            const int32_t want = 4 * ((int32_t)adc - (int32_t)TARGET_ADC);
            duty = want <= 0 ? 0 : want >= 255 ? 255 : (uint8_t)want;
            OCR2A = duty;
            if (!reached && adc <= TARGET_ADC) {
                reached = 1;
                uart_put('o');
                uart_put('k');
                uart_put('\n');
            }
        }
        if ((uint16_t)(now - reported_at) >= 500) {
            reported_at = now;
            uart_put('T');
            uart_put(':');
            uart_number(last_adc);
            uart_put(' ');
            uart_put('D');
            uart_put(':');
            uart_number(duty);
            uart_put('\n');
        }
        _delay_loop_2(4000); /* 4 cycles per count: 1 ms */
    }
}
