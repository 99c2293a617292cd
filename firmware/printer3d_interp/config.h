/*
 * printer3d_interp's machine: pins of the interpolator MCU (an ATmega2560 at
 * 16 MHz: seed 001 leaves the interpolator's platform open, digest §1) and
 * the constants the thesis names or leaves to us.
 */
#ifndef PRINTER3D_INTERP_CONFIG_H
#define PRINTER3D_INTERP_CONFIG_H

#include <avr/io.h>

/* One BLU is the carriage travel of one full step (§3, "Στοιχειώδες Μήκος").
 * The listing's BLU_PER_MM is 1000 (1 um); our printer's axes are T8x2 lead
 * screws (2 mm per turn, 200 full steps: 100 steps/mm), which the drive
 * boards' full-step sequence can actually follow. */
#ifndef BLU_PER_MM
#define BLU_PER_MM 100L
#endif

/* "Dynamic dT" ramp length in interpolation ticks (Code 4.7: #define N 50). */
#ifndef RAMP_N
#define RAMP_N 50
#endif

/* Extruder: SP steps per interpolation tick while depositing (§4.7; the
 * thesis leaves SP open). SP = 1/8: with 100 BLU/mm of path, 12.5 E full
 * steps per mm of path. */
#define SP_NUM 1
#define SP_DEN 8
/* Anti-ooze retract on every extruder disable (§4.7: "by some steps"), and
 * the same steps primed back before the next depositing move; 2.5 ms apart
 * (400 steps/s: the unipolar motor starts there without a ramp). */
#define RETRACT_STEPS 40
#define BURST_PERIOD_US 2500UL

/* Homing (G28): towards the min switches at 300 mm/min, 2 ms per step,
 * giving up after 300 mm of travel. */
#define HOMING_PERIOD_US 2000UL
#define HOMING_MAX_BLU (300L * BLU_PER_MM)

/* Feeds: mm/min (modal F); 600 mm/min until the first F. Feeds are limited to
 * what the drive boards' motors follow (the unipolar preset at 12 V slips
 * near 450 rpm on the bench): at most 600 mm/min = 1000 full steps/s, 300 rpm. */
#define DEFAULT_FEED_MM_MIN 600L
#define MAX_FEED_MM_MIN 600L
#define MIN_FEED_MM_MIN 1L

/* Travel: positions outside -1000..+1000 mm are refused (error:range). */
#define MAX_ABS_MM 1000L

/* Output pins. PORTA: the four STEP lines and a TICK strobe that is high
 * while an interpolation execution runs (a scope's view of the DDA). */
#define STEP_PORT PORTA
#define STEP_DDR DDRA
#define X_STEP _BV(PA0)
#define Y_STEP _BV(PA1)
#define Z_STEP _BV(PA2)
#define E_STEP _BV(PA3)
#define TICK_PIN _BV(PA7)
/* PORTC: DIR (high = clockwise = +, §3.2.1) on PC0..PC3, ENABLE (high =
 * enabled) on PC4..PC7, X Y Z E in that order. */
#define DIR_PORT PORTC
#define DIR_DDR DDRC
#define DIR_BIT(axis) _BV(axis)
#define ENABLE_BITS 0xF0
/* PORTK: the min limit switches of X, Y, Z on PK0..PK2; a closed switch
 * pulls the pin to 0 V (§2.6.2), pull-ups on. */
#define SWITCH_PIN PINK
#define SWITCH_PORT PORTK
#define SWITCH_BIT(axis) _BV(axis)

enum { AXIS_X, AXIS_Y, AXIS_Z, AXIS_E, AXES };

#endif
