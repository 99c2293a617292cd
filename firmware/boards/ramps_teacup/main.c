/*
 * ramps_teacup - a RAMPS 1.4 firmware (ATmega2560, 16 MHz) in the style of
 * Teacup and Marlin: a timer-driven step interrupt, thermistor sampling from
 * a timer interrupt with oversampling, a soft-PWM output driven from the same
 * interrupt, a hardware-PWM heater, a line-oriented serial protocol. Nothing
 * in it knows about the bench.
 *
 * RAMPS 1.4 pins (Arduino Mega numbering):
 *   X STEP  A0  = PF0      X DIR  A1 = PF1      X EN  D38 = PD7 (active low)
 *   T0      A13 = PK5 = ADC13 (MUX5:0 = 100101, 2560 §26.8.1 Table 26-4)
 *   HEATER  D10 = PB4 = OC2A: Timer2 fast PWM, clk/64 (Marlin's analogWrite)
 *   D9      D9  = PH6: soft PWM from the temperature interrupt (Marlin's
 *                 FAN_SOFT_PWM / soft_pwm_amount)
 *
 * Timers:
 *   Timer0  fast PWM, clk/8, OCR0B = 128, COMPB interrupt every 256 * 8 =
 *           2048 cycles ("temperature ISR"). Each tick: soft PWM (7-bit
 *           counter: PH6 on at count 0 if amount > 0, off when count reaches
 *           amount / 2: duty = (amount / 2) / 128, period 128 ticks), and the
 *           ADC state machine: even ticks start a conversion of ADC13, odd
 *           ticks add ADC to an accumulator; 16 samples make one reading
 *           (Marlin's OVERSAMPLENR = 16): `current_raw` = sum of 16 codes.
 *   Timer1  CTC, clk/8, OCR1A = 1999: step interrupt at 1000 steps/s while a
 *           move is pending: STEP high, position update, STEP low.
 *   Timer2  fast PWM on OC2A, clk/64: duty (OCR2A + 1) / 256.
 *   USART0  115200 baud (U2X, UBRR = 16), receive interrupt into a line buffer.
 *
 * Commands (one per line, answered "ok"):
 *   G1 X<n>      move X by n steps (negative: DIR low)
 *   M42 P10 S<v> heater PWM on D10 (0 = off, 255 = on, else OCR2A = v)
 *   M106 S<v>    soft PWM amount on D9 (0..255)
 *   M105         report "ok T:<current_raw>"
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "avrbench_mcu.h"
#include "fw_line.h"
#include "fw_uart.h"

AVRBENCH_MCU_SECTION();

#define OVERSAMPLENR 16
#define THERMISTOR_CHANNEL 13

volatile uint16_t current_raw;
volatile uint16_t samples;
volatile int16_t x_position;
volatile uint16_t steps_left;
volatile uint8_t soft_pwm_amount;

static fw_line_t line; /* FW_LINE_MAX 31 */

/* --- temperature + soft PWM interrupt (Timer0 COMPB) ------------------------ */
ISR(TIMER0_COMPB_vect)
{
    static uint8_t pwm_count;
    static uint8_t adc_state;
    static uint16_t acc;
    static uint8_t n;

    if (pwm_count == 0) {
        if (soft_pwm_amount > 1) PORTH |= (1 << PH6);
    }
    if ((soft_pwm_amount >> 1) <= pwm_count) PORTH &= (uint8_t) ~(1 << PH6);
    pwm_count = (uint8_t)((pwm_count + 1) & 0x7F);

    if (adc_state == 0) {
        ADMUX = (1 << REFS0) | (THERMISTOR_CHANNEL & 0x07);
        ADCSRB = (1 << MUX5);
        ADCSRA |= (1 << ADSC);
        adc_state = 1;
    } else {
        acc += ADC;
        adc_state = 0;
        if (++n == OVERSAMPLENR) {
            current_raw = acc;
            ++samples;
            acc = 0;
            n = 0;
        }
    }
}

/* --- step interrupt (Timer1 COMPA) ------------------------------------------ */
ISR(TIMER1_COMPA_vect)
{
    if (steps_left == 0) {
        TIMSK1 &= (uint8_t) ~(1 << OCIE1A);
        PORTD |= (1 << PD7); /* disable the driver (EN high) */
        return;
    }
    PORTF |= (1 << PF0);
    --steps_left;
    if (PORTF & (1 << PF1)) {
        ++x_position;
    } else {
        --x_position;
    }
    PORTF &= (uint8_t) ~(1 << PF0);
}

static void move_x(int16_t steps)
{
    while (steps_left) {
    }
    if (steps >= 0) {
        PORTF |= (1 << PF1);
    } else {
        PORTF &= (uint8_t) ~(1 << PF1);
        steps = (int16_t)-steps;
    }
    PORTD &= (uint8_t) ~(1 << PD7); /* enable the driver */
    cli();
    steps_left = (uint16_t)steps;
    TCNT1 = 0;
    TIFR1 = (1 << OCF1A);
    TIMSK1 |= (1 << OCIE1A);
    sei();
}

static void heater_pwm(uint8_t v)
{
    if (v == 0 || v == 255) {
        TCCR2A &= (uint8_t) ~((1 << COM2A1) | (1 << COM2A0));
        if (v) {
            PORTB |= (1 << PB4);
        } else {
            PORTB &= (uint8_t) ~(1 << PB4);
        }
    } else {
        OCR2A = v;
        TCCR2A |= (1 << COM2A1);
    }
}

static const char* find(const char* s, char key)
{
    const char* p = strchr(s, key);
    return p ? p + 1 : 0;
}

static void execute(const char* cmd)
{
    const char* arg;
    if (cmd[0] == 'G' && atoi(cmd + 1) == 1 && (arg = find(cmd, 'X'))) {
        move_x((int16_t)atoi(arg));
    } else if (cmd[0] == 'M') {
        const int m = atoi(cmd + 1);
        if (m == 42 && (arg = find(cmd, 'P')) && atoi(arg) == 10 && (arg = find(cmd, 'S'))) {
            heater_pwm((uint8_t)atoi(arg));
        } else if (m == 106 && (arg = find(cmd, 'S'))) {
            soft_pwm_amount = (uint8_t)atoi(arg);
        } else if (m == 105) {
            fw_uart_puts("ok T:");
            fw_uart_put_u32(current_raw);
            fw_uart_puts("\n");
            return;
        }
    }
    fw_uart_puts("ok\n");
}

int main(void)
{
    DDRF |= (1 << PF0) | (1 << PF1);
    DDRD |= (1 << PD7);
    PORTD |= (1 << PD7); /* driver disabled */
    DDRB |= (1 << PB4);
    DDRH |= (1 << PH6);

    fw_uart_init(16, 1); /* 115200 baud with U2X */

    ADCSRA = (1 << ADEN) | (1 << ADPS2) | (1 << ADPS1) | (1 << ADPS0); /* /128: 125 kHz */
    DIDR2 = (1 << ADC13D);

    TCCR0A = (1 << WGM01) | (1 << WGM00);
    TCCR0B = (1 << CS01);
    OCR0B = 128;
    TIMSK0 = (1 << OCIE0B);

    TCCR1A = 0;
    TCCR1B = (1 << WGM12) | (1 << CS11);
    OCR1A = 1999;

    TCCR2A = (1 << WGM21) | (1 << WGM20);
    TCCR2B = (1 << CS22);

    sei();
    fw_uart_puts("start\n");
    for (;;) {
        const int16_t c = fw_uart_getc();
        if (c < 0) {
            fw_uart_idle(); /* until a byte or a timer interrupt */
        } else if (fw_line_feed(&line, (char)c)) {
            if (line.overflow) fw_uart_puts("error: line too long\n");
            else execute(line.text);
        }
    }
}
