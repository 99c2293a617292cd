/*
 * pid_heater - RAMPS 1.4 hot end held at a target by PID (Marlin 1.1's
 * defaults, common/thermal.h), no protection of any kind.
 *
 * Every 100 ms: 16 conversions of A13 (T0, EPCOS B57560G104F with the 4.7 kohm
 * pull-up), the temperature, one PID step, the heater duty on D10 (OC2A,
 * 61 Hz PWM). The target is TARGET_C (compile time, default 200 degC) in the
 * global target_c, which a test may change.
 *
 * Exports: temp_x10 (0.1 degC), heater_duty (0..255), adc_sum (16 samples),
 * samples (PID steps done).
 */
#include <stdint.h>

#include "avrbench_mcu.h"
#include "thermal.h"

AVRBENCH_MCU_SECTION();

#ifndef TARGET_C
#define TARGET_C 200
#endif

volatile int16_t target_c = TARGET_C;
volatile int16_t temp_x10;
volatile uint8_t heater_duty;
volatile uint16_t adc_sum;
volatile uint16_t samples;

int main(void)
{
    thermal_init();
    pid_state_t pid = {0};
    uint16_t next = ticks;
    for (;;) {
        adc_sum = adc_read16(THERMAL_HOTEND_CHANNEL);
        const float t = thermistor_degC(adc_sum);
        temp_x10 = (int16_t)(t * 10.0f);
        heater_duty = pid_step(&pid, (float)target_c, t, 0.1f);
        heater_set(heater_duty);
        ++samples;
        next += 10;
        wait_ticks(next);
    }
}
