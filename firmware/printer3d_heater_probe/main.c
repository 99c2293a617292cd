/*
 * printer3d_heater_probe - a TWI master on an ATmega2560 standing in for
 * seed 001's interpolator on the heater link (firmware/printer3d_heater):
 * writes the setpoint SETPOINT_C once, then every 500 ms reads the heater
 * MCU's 5 bytes (temperature in 0.1 degC, setpoint, TEMP_OK). 100 kHz
 * (TWBR = 72, 2560 §24.5.2: 16 MHz / (16 + 2 * 72)).
 *
 * Globals for tests: seen_temp_x10, seen_setpoint, seen_ok, reads, errors.
 */
#include <avr/io.h>
#include <stdint.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define HEATER 0x30
#ifndef SETPOINT_C
#define SETPOINT_C 200
#endif

volatile int16_t seen_temp_x10;
volatile uint16_t seen_setpoint;
volatile uint8_t seen_ok;
volatile uint16_t reads;
volatile uint16_t errors;

static uint8_t wait(void)
{
    while (!(TWCR & _BV(TWINT))) {
    }
    return TWSR & 0xF8;
}

static uint8_t start(uint8_t sla_rw)
{
    TWCR = _BV(TWINT) | _BV(TWSTA) | _BV(TWEN);
    const uint8_t s = wait();
    if (s != 0x08 && s != 0x10) return 0;
    TWDR = sla_rw;
    TWCR = _BV(TWINT) | _BV(TWEN);
    const uint8_t a = wait();
    return a == 0x18 || a == 0x40;
}

static void stop(void) { TWCR = _BV(TWINT) | _BV(TWSTO) | _BV(TWEN); }

static void write_setpoint(uint16_t c)
{
    if (!start((uint8_t)(HEATER << 1))) {
        ++errors;
        stop();
        return;
    }
    const uint8_t bytes[2] = {(uint8_t)c, (uint8_t)(c >> 8)};
    for (uint8_t i = 0; i < 2; ++i) {
        TWDR = bytes[i];
        TWCR = _BV(TWINT) | _BV(TWEN);
        if (wait() != 0x28) ++errors;
    }
    stop();
}

static void read_status(void)
{
    uint8_t b[5];
    if (!start((uint8_t)((HEATER << 1) | 1))) {
        ++errors;
        stop();
        return;
    }
    for (uint8_t i = 0; i < 5; ++i) {
        TWCR = (uint8_t)(_BV(TWINT) | _BV(TWEN) | (i < 4 ? _BV(TWEA) : 0));
        wait();
        b[i] = TWDR;
    }
    stop();
    seen_temp_x10 = (int16_t)(b[0] | (b[1] << 8));
    seen_setpoint = (uint16_t)(b[2] | (b[3] << 8));
    seen_ok = b[4];
    ++reads;
}

int main(void)
{
    TWBR = 72;
    TWSR = 0;
    _delay_ms(10);
    write_setpoint(SETPOINT_C);
    for (;;) {
        _delay_ms(500);
        read_status();
    }
}
