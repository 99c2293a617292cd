#include "thermal.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <math.h>

volatile uint16_t ticks;

ISR(TIMER1_COMPA_vect)
{
    ++ticks;
}

void thermal_init(void)
{
    /* ADC: enable, clk/128; AVCC reference. */
    ADMUX = _BV(REFS0);
    ADCSRA = _BV(ADEN) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0);

    /* Heater off until the first heater_set(). */
    DDRB |= _BV(PB4);
    PORTB &= (uint8_t)~_BV(PB4);
    TCCR2A = _BV(WGM21) | _BV(WGM20);            /* fast PWM, TOP 0xFF, OC2A disconnected */
    TCCR2B = _BV(CS22) | _BV(CS21) | _BV(CS20);  /* clk/1024 */

    DDRH |= _BV(PH6);
    PORTH &= (uint8_t)~_BV(PH6);

    /* 100 Hz tick: 16e6 / 64 / 2500. */
    OCR1A = 2499;
    TCCR1A = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11) | _BV(CS10);
    TIMSK1 = _BV(OCIE1A);
    sei();
}

uint16_t adc_read(uint8_t channel)
{
    if (channel >= 8) ADCSRB |= _BV(MUX5); else ADCSRB &= (uint8_t)~_BV(MUX5);
    ADMUX = (uint8_t)(_BV(REFS0) | (channel & 0x07));
    ADCSRA |= _BV(ADSC);
    while (ADCSRA & _BV(ADSC)) {
    }
    return ADC;
}

uint16_t adc_read16(uint8_t channel)
{
    uint16_t sum = 0;
    for (uint8_t i = 0; i < 16; ++i) sum += adc_read(channel);
    return sum;
}

float thermistor_degC(uint16_t sum16)
{
    const float a = (float)sum16 / 16.0f;
    if (a >= 1023.5f) return -273.15f;
    if (a <= 0.0f) return 1000.0f;
    const float r = 4700.0f * a / (1024.0f - a);
    const float l = logf(r);
    /* Steinhart-Hart through the three datasheet points (see thermal.h). */
    const float inv_t = 7.2213631e-4f + 2.1676657e-4f * l + 8.9293580e-8f * l * l * l;
    return 1.0f / inv_t - 273.15f;
}

void heater_set(uint8_t duty)
{
    if (duty == 0 || duty == 255) {
        TCCR2A &= (uint8_t)~(_BV(COM2A1) | _BV(COM2A0));
        if (duty) PORTB |= _BV(PB4); else PORTB &= (uint8_t)~_BV(PB4);
    } else {
        OCR2A = duty;
        TCCR2A |= _BV(COM2A1);  /* non-inverting: set at BOTTOM, clear on match */
    }
}

void fan_set(uint8_t on)
{
    if (on) PORTH |= _BV(PH6); else PORTH &= (uint8_t)~_BV(PH6);
}

void wait_ticks(uint16_t until)
{
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) {
        cli();
        const uint16_t now = ticks;
        if ((int16_t)(now - until) >= 0) {
            sei();
            return;
        }
        sleep_enable();
        sei();
        sleep_cpu();
        sleep_disable();
    }
}

uint8_t pid_step(pid_state_t *pid, float target, float measured, float dt_s)
{
    const float kp = 22.2f, ki = 1.08f, kd = 114.0f, k1 = 0.95f;
    const float error = target - measured;
    float out;
    if (target <= 0.0f || error < -10.0f) {
        pid->in_range = 0;
        out = 0.0f;
    } else if (error > 10.0f) {
        pid->in_range = 0;
        out = 255.0f;
    } else {
        if (!pid->in_range) {
            pid->in_range = 1;
            pid->integral = 0.0f;
            pid->dterm = 0.0f;
            pid->previous = measured;
        }
        pid->integral += error * dt_s;
        /* anti-windup: the integral term alone never exceeds full output */
        if (pid->integral * ki > 255.0f) pid->integral = 255.0f / ki;
        if (pid->integral < 0.0f) pid->integral = 0.0f;
        pid->dterm = (1.0f - k1) * kd * (pid->previous - measured) / dt_s + k1 * pid->dterm;
        out = kp * error + ki * pid->integral + pid->dterm;
        if (out > 255.0f) out = 255.0f;
        if (out < 0.0f) out = 0.0f;
    }
    pid->previous = measured;
    return (uint8_t)out;
}
