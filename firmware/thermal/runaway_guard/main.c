/*
 * runaway_guard - pid_heater plus Marlin-style protection; on any error the
 * heater goes off for good and `error` says why:
 *
 *   1 HEATING_FAILED  heating watch (Marlin 1.1 Configuration_adv.h:
 *                     WATCH_TEMP_PERIOD 20 s, WATCH_TEMP_INCREASE 2 degC):
 *                     while heating towards the target, the temperature must
 *                     rise 2 degC every 20 s.
 *   2 THERMAL_RUNAWAY  once at the target (THERMAL_PROTECTION_PERIOD 40 s,
 *                     THERMAL_PROTECTION_HYSTERESIS 4 degC): below
 *                     target - 4 degC for more than 40 s.
 *   3 MINTEMP         below HEATER_0_MINTEMP 5 degC (Marlin default): open sensor.
 *   4 MAXTEMP         above HEATER_0_MAXTEMP 275 degC (Marlin default): shorted
 *                     sensor or a heater that cannot be switched off.
 *
 * Exports as pid_heater, plus error and error_at_s (seconds since start).
 */
#include <stdint.h>

#include "avrbench_mcu.h"
#include "thermal.h"

AVRBENCH_MCU_SECTION();

#ifndef TARGET_C
#define TARGET_C 200
#endif

#define WATCH_PERIOD_S 20
#define WATCH_INCREASE_C 2.0f
#define RUNAWAY_PERIOD_S 40
#define RUNAWAY_HYSTERESIS_C 4.0f
#define MINTEMP_C 5.0f
#define MAXTEMP_C 275.0f

volatile int16_t target_c = TARGET_C;
volatile int16_t temp_x10;
volatile uint8_t heater_duty;
volatile uint16_t adc_sum;
volatile uint16_t samples;
volatile uint8_t error;
volatile uint16_t error_at_s;

static void trip(uint8_t why)
{
    heater_set(0);
    heater_duty = 0;
    error = why;
    error_at_s = samples / 10;
}

int main(void)
{
    thermal_init();
    pid_state_t pid = {0};
    uint16_t next = ticks;

    uint8_t watching = 0, stable = 0, below = 0;
    uint16_t watch_deadline = 0, below_since = 0;
    float watch_target = 0.0f;

    for (;;) {
        adc_sum = adc_read16(THERMAL_HOTEND_CHANNEL);
        const float t = thermistor_degC(adc_sum);
        temp_x10 = (int16_t)(t * 10.0f);
        const uint16_t now_s = samples / 10;
        const float target = (float)target_c;
        if (!error) {
            if (t < MINTEMP_C) {
                trip(3);
            } else if (t > MAXTEMP_C) {
                trip(4);
            } else {
                /* Heating watch: armed while well below the target. */
                if (!stable && !watching && t < target - (WATCH_INCREASE_C + RUNAWAY_HYSTERESIS_C + 1.0f)) {
                    watching = 1;
                    watch_target = t + WATCH_INCREASE_C;
                    watch_deadline = now_s + WATCH_PERIOD_S;
                }
                if (watching && (int16_t)(now_s - watch_deadline) >= 0) {
                    if (t < watch_target) {
                        trip(1);
                    } else {
                        watching = 0;  /* re-armed on the next pass while still heating */
                    }
                }
                /* Runaway at the target. */
                if (!stable && t >= target) {
                    stable = 1;
                    watching = 0;
                }
                if (stable) {
                    if (t < target - RUNAWAY_HYSTERESIS_C) {
                        if (!below) {
                            below = 1;
                            below_since = now_s;
                        } else if ((int16_t)(now_s - below_since) > RUNAWAY_PERIOD_S) {
                            trip(2);
                        }
                    } else {
                        below = 0;
                    }
                }
            }
        }
        if (!error) {
            heater_duty = pid_step(&pid, target, t, 0.1f);
            heater_set(heater_duty);
        }
        ++samples;
        next += 10;
        wait_ticks(next);
    }
}
