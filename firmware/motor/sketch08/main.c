/*
 * sketch08 - seed 003's sketch_08 (digest §6): "Enter Speed", then each
 * number read with Serial.parseInt() moves AF_Stepper motor(200, 2): > 0,
 * 1000 steps FORWARD DOUBLE at that many rpm; < 0, BACKWARD at its
 * magnitude; 0, release. The digest gives its behaviour, not its text: this
 * is that behaviour with the library code it names - Stream::parseInt of
 * Arduino 1.6 (skip to a digit or '-', read digits, a 1000 ms timeout that
 * returns 0), and AF_Stepper's setSpeed/step with their whole-millisecond
 * delays (as sketch06). So a speed typed with a line ending is followed, a
 * second later, by the 0 that parseInt returns for the '\n' alone: release.
 *
 * Bench instrumentation, not in the sketch: position (full steps, signed),
 * moves_done, releases.
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
volatile uint16_t releases;


/* Stream::timedPeek with the default 1000 ms timeout: -1 when nothing came. */
static int timed_peek(void)
{
    const unsigned long start = millis();
    do {
        if (serial_available()) return rx_buffer[rx_tail];
    } while (millis() - start < 1000);
    return -1;
}

static long parse_int(void)
{
    int c;
    for (;;) { /* peekNextDigit */
        c = timed_peek();
        if (c < 0) return 0;
        if (c == '-' || (c >= '0' && c <= '9')) break;
        serial_read();
    }
    uint8_t negative = 0;
    long value = 0;
    do {
        if (c == '-') {
            negative = 1;
        } else if (c >= '0' && c <= '9') {
            value = value * 10 + c - '0';
        }
        serial_read();
        c = timed_peek();
    } while (c >= '0' && c <= '9');
    return negative ? -value : value;
}

int main(void)
{
    arduino_init();
    afstepper_init();
    serial_begin();
    print_str("Enter Speed");
    println();
    for (;;) {
        if (!serial_available()) continue;
        const long spd = parse_int();
        if (spd > 0) {
            afstepper_set_speed((uint16_t)spd);
            afstepper_step(1000, FORWARD, DOUBLE, &position);
            moves_done++;
        } else if (spd < 0) {
            afstepper_set_speed((uint16_t)-spd);
            afstepper_step(1000, BACKWARD, DOUBLE, &position);
            moves_done++;
        } else {
            afstepper_release();
            releases++;
        }
    }
}
