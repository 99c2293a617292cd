/*
 * pwm_heater - RAMPS 1.4 heater at a fixed duty, for the plant's open-loop
 * tests (step response, steady state versus duty, energy balance, faults).
 *
 *   D10 = PB4 = OC2A: heater_set(HEATER_DUTY) (common/thermal.h: 61.04 Hz
 *   fast PWM, on for HEATER_DUTY + 1 of every 256 timer counts; 0 = off,
 *   255 = on continuously).
 *   D9 = PH6: the fan, on when FAN_ON is 1.
 *   Every 100 ms: adc_sum = 16 conversions of A13 (T0), temp_x10 = its
 *   temperature in 0.1 degC (EPCOS B57560G104F, 4.7 kohm pull-up).
 */
#include <stdint.h>

#include "avrbench_mcu.h"
#include "thermal.h"

AVRBENCH_MCU_SECTION();

#ifndef HEATER_DUTY
#define HEATER_DUTY 255
#endif
#ifndef FAN_ON
#define FAN_ON 0
#endif

volatile uint16_t adc_sum;
volatile int16_t temp_x10;
volatile uint16_t samples;

int main(void)
{
    thermal_init();
    heater_set(HEATER_DUTY);
    fan_set(FAN_ON);
    uint16_t next = ticks;
    for (;;) {
        adc_sum = adc_read16(THERMAL_HOTEND_CHANNEL);
        temp_x10 = (int16_t)(thermistor_degC(adc_sum) * 10.0f);
        ++samples;
        next += 10;
        wait_ticks(next);
    }
}
