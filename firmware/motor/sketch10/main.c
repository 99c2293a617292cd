/*
 * sketch10 - seed 003's sketch_10 as printed (the thesis' listing, l.2673-
 * 2715): "motor_set.", then for every byte received its value printed
 * (Serial.println(byte): a decimal number), and on 'Z' (90) 2000 DOUBLE
 * steps of AF_Stepper motor1(200, 2) at 100 rpm, FORWARD and BACKWARD in
 * turn, each followed by setSpeed(0) and release(). setSpeed(0) divides by
 * zero in AFMotor (usperstep = 60000000 / (revsteps * rpm), digest §6):
 * the AVR's 32-bit division routine returns all ones for it, no trap, and
 * the next move's setSpeed(100) overwrites it before any step uses it. The
 * library code as in sketch08 (AFMotor's whole-millisecond step delays).
 *
 * Bench instrumentation, not in the sketch: position (full steps, signed),
 * moves_done; usperstep is AFMotor's own variable.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#define AFSTEPPER_ARDUINO_IO
#include "afstepper.h"
#include "arduino_runtime.h"
#include "afstepper_timed.h"
#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile int32_t position;
volatile uint16_t moves_done;

int main(void)
{
    arduino_init();
    afstepper_init();
    serial_begin();
    print_str("motor_set.");
    println();
    uint8_t count = 0;
    for (;;) {
        while (serial_available()) {
            const uint8_t dir = serial_read();
            print_ulong(dir);
            println();
            if (dir == 90) {
                afstepper_set_speed(100);
                afstepper_step(2000, count == 0 ? FORWARD : BACKWARD, DOUBLE, &position);
                count = count == 0 ? 1 : 0;
                afstepper_set_speed(0);
                afstepper_release();
                moves_done++;
            }
        }
    }
}
