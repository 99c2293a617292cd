/*
 * printer3d_heater - seed 001's hot-end control (§3.3, digest §5) on its own
 * ATmega32 at 16 MHz, with the setpoint and the temperature on a TWI link to
 * the interpolator MCU: the drive boards' UART pins carry DIR and ENABLE
 * (digest §1), so the heater gets an MCU of its own, a TWI slave.
 *
 * As the thesis designs it: the thermistor on ADC2 (PA2) in the lower leg of
 * a divider to AVCC, the heater's MOSFET on OC2 = PD7, Timer2 fast PWM at
 * clk/128 (16 MHz / 128 / 256 = 488.28 Hz, 2.048 ms), TEMP_OK on PD6 while
 * |setpoint - T| < 5, and the discrete PID OCR2 = 200 e + sum(e) + 500 (e -
 * e_prev) clamped to 0..255. Unlike the listing (digest §9.4-9.6): e in degC
 * (a float) from the thermistor's resistance (10-bit conversion; beta = 3950,
 * 100 kohm at 25 degC; R_fixed = 891.7 ohm), the integral only accumulates
 * while the output is not saturated and is bounded (anti-windup), and the
 * heater is off (OC2 disconnected, PD7 low) with setpoint 0. One PID step per
 * 100 ms (Timer1), from a conversion of ADC2.
 *
 * TWI (slave address 0x30, 7-bit): a write of 2 bytes sets the setpoint in
 * degC (little-endian; 0 = off; at most 300); a read returns 5 bytes:
 * temperature in 0.1 degC (int16 LE), the setpoint (uint16 LE), TEMP_OK.
 *
 * Globals for tests: temp_x10, setpoint_c, duty, samples, temp_ok.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <math.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define TWI_ADDRESS 0x30
#define R_FIXED_OHM 891.7f
#define R0_OHM 100000.0f
#define T0_K 298.15f
#define BETA 3950.0f
#define KP 200
#define KI 1
#define KD 500
#define TEMP_OK_BAND_C 5

volatile int16_t temp_x10;
volatile uint16_t setpoint_c;
volatile uint8_t duty;
volatile uint16_t samples;
volatile uint8_t temp_ok;

static float integral;
static float last_error;

/* --- heater PWM (Timer2) -------------------------------------------------------- */
static void heater(uint8_t on, uint8_t ocr)
{
    if (!on) {
        TCCR2 = _BV(WGM21) | _BV(WGM20) | _BV(CS22) | _BV(CS20); /* OC2 disconnected */
        PORTD &= (uint8_t)~_BV(PD7);
        duty = 0;
        return;
    }
    OCR2 = ocr;
    TCCR2 = _BV(WGM21) | _BV(WGM20) | _BV(COM21) | _BV(CS22) | _BV(CS20);
    duty = ocr;
}

/* --- temperature ----------------------------------------------------------------- */
static float degc_from_code(uint16_t code)
{
    if (code == 0) return -273.15f;   /* shorted */
    if (code >= 1023) return 999.0f;  /* open */
    /* Lower leg: V / Vref = R / (R + R_fixed). */
    const float r = R_FIXED_OHM * (float)code / (1024.0f - (float)code);
    return 1.0f / (1.0f / T0_K + logf(r / R0_OHM) / BETA) - 273.15f;
}

static void pid_step(float t)
{
    if (setpoint_c == 0) {
        integral = 0;
        heater(0, 0);
        return;
    }
    const float e = (float)setpoint_c - t;
    const float out = KP * e + KI * integral + KD * (e - last_error);
    last_error = e;
    /* Anti-windup: integrate only while the output is inside 0..255, and bound it. */
    if (out > 0 && out < 255) {
        integral += e;
        if (integral > 255) integral = 255;
        if (integral < -255) integral = -255;
    }
    /* OCR2 = 0 still gives 1/256 (fast PWM, digest §10.4); the PWM keeps its
     * period, so every gate edge is on the 2.048 ms grid. */
    heater(1, out <= 0 ? 0 : out >= 255 ? 255 : (uint8_t)lroundf(out));
}

ISR(ADC_vect)
{
    const float t = degc_from_code(ADC);
    temp_x10 = (int16_t)lroundf(t * 10.0f);
    ++samples;
    pid_step(t);
    const float diff = (float)setpoint_c - t;
    temp_ok = setpoint_c != 0 && diff < TEMP_OK_BAND_C && diff > -TEMP_OK_BAND_C;
    if (temp_ok) PORTD |= _BV(PD6);
    else PORTD &= (uint8_t)~_BV(PD6);
}

/* Timer1 compare B every 100 ms starts a conversion (ADC auto trigger, ADTS = 101). */
EMPTY_INTERRUPT(TIMER1_COMPB_vect);

/* --- TWI slave ---------------------------------------------------------------------- */
static uint8_t rx[2], tx[5], index_;

ISR(TWI_vect)
{
    switch (TWSR & 0xF8) {
        case 0x60: /* own SLA+W, ACKed */
            index_ = 0;
            break;
        case 0x80: /* data byte received, ACKed */
            if (index_ < sizeof rx) rx[index_++] = TWDR;
            if (index_ == sizeof rx) {
                const uint16_t s = (uint16_t)(rx[0] | (rx[1] << 8));
                setpoint_c = s > 300 ? 300 : s;
            }
            break;
        case 0xA8: /* own SLA+R, ACKed: the first byte */
            tx[0] = (uint8_t)temp_x10;
            tx[1] = (uint8_t)((uint16_t)temp_x10 >> 8);
            tx[2] = (uint8_t)setpoint_c;
            tx[3] = (uint8_t)(setpoint_c >> 8);
            tx[4] = temp_ok;
            index_ = 0;
            /* fall through */
        case 0xB8: /* data byte sent, ACKed: the next */
            TWDR = index_ < sizeof tx ? tx[index_++] : 0xFF;
            break;
        default: /* 0xA0 stop, 0xC0/0xC8 read done, errors */
            break;
    }
    TWCR = _BV(TWINT) | _BV(TWEA) | _BV(TWEN) | _BV(TWIE);
}

int main(void)
{
    DDRD = _BV(PD6) | _BV(PD7);
    PORTD = 0;
    heater(0, 0);
    /* ADC2, AVCC reference, right adjusted 10 bits, clk/128 = 125 kHz. */
    ADMUX = _BV(REFS0) | 2;
    SFIOR = (uint8_t)((SFIOR & 0x1F) | _BV(ADTS2) | _BV(ADTS0)); /* Timer1 compare match B */
    ADCSRA = _BV(ADEN) | _BV(ADATE) | _BV(ADIE) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0);
    /* Timer1 CTC at clk/256: 16 MHz / 256 / 6250 = 10 Hz. */
    OCR1A = 6249;
    OCR1B = 6249;
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS12);
    TIMSK = _BV(OCIE1B);
    TWAR = (uint8_t)(TWI_ADDRESS << 1);
    TWCR = _BV(TWEA) | _BV(TWEN) | _BV(TWIE);
    /* Everything happens in interrupts; sleep in between (idle mode: the
     * timers, the ADC and the TWI run on). */
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();
    sei();
    for (;;) sleep_cpu();
}
