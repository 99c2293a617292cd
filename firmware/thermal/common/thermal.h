/*
 * thermal.h - what the thermal firmwares share (RAMPS 1.4 on a Mega 2560):
 *
 *   ADC      AVCC reference (REFS1:0 = 01), prescaler 128 (125 kHz at 16 MHz),
 *            single conversions polled on ADSC; channels >= 8 set ADCSRB.MUX5
 *            (ATmega2560 §26.8.1, Table 26-4).
 *   heater   D10 = PB4 = OC2A, Timer2 fast PWM (WGM2 = 011), clk/1024:
 *            16e6 / 1024 / 256 = 61.04 Hz. heater_set(d): 0 = pin low and
 *            255 = pin high with the compare output disconnected, else
 *            non-inverting OC2A with OCR2A = d, high for d + 1 of 256 counts.
 *   fan      D9 = PH6 (RAMPS EFB fan MOSFET), plain output.
 *   tick     Timer1 CTC at 100 Hz (OCR1A = 2499, clk/64): `ticks` counts.
 *   sensor   EPCOS B57560G104F on A13 = PK5 (ADC13) with the RAMPS 4.7 kohm
 *            pull-up: R = 4700 * a / (1024 - a) for the average code a, then
 *            Steinhart-Hart with A, B, C through the datasheet points
 *            (25 degC, 100 kohm), (150 degC, 1641.9 ohm), (250 degC, 226.15 ohm).
 */
#ifndef THERMAL_H
#define THERMAL_H

#include <stdint.h>

#define THERMAL_HOTEND_CHANNEL 13 /* A13 = PK5, RAMPS T0 */

extern volatile uint16_t ticks;   /* 10 ms each */

void thermal_init(void);          /* ADC, heater PWM, fan pin, tick; enables interrupts */
uint16_t adc_read(uint8_t channel);
/* Sum of 16 conversions (Marlin's OVERSAMPLENR). */
uint16_t adc_read16(uint8_t channel);
/* Temperature in degC from a 16-sample sum; -273 for an open sensor (code 1023
 * everywhere is R = infinity), a very high value for a short (code 0). */
float thermistor_degC(uint16_t sum16);
void heater_set(uint8_t duty);
void fan_set(uint8_t on);
/* Sleeps (idle) until `ticks` reaches `until`. */
void wait_ticks(uint16_t until);

/* Marlin-style PID (Marlin 1.1 Configuration.h defaults DEFAULT_Kp 22.2,
 * DEFAULT_Ki 1.08 (1/s), DEFAULT_Kd 114 (s), output 0..255, PID_FUNCTIONAL_RANGE
 * 10 degC: full on/off outside it, integral reset when entering it; the
 * derivative on the measurement, smoothed with PID_K1 0.95). */
typedef struct {
    float integral;
    float dterm;
    float previous;
    uint8_t in_range;
} pid_state_t;
uint8_t pid_step(pid_state_t *pid, float target, float measured, float dt_s);

#endif
