#include "heater_link.h"

#include <avr/io.h>

#define HEATER_ADDRESS 0x30
/* A byte takes 9 SCL periods of 10 us; a stretching slave (its PID runs in
 * an interrupt) may hold SCL a few ms. Give up after ~20 ms per step. */
#define WAIT_LOOPS 40000U

static uint8_t wait_twint(uint8_t *status)
{
    for (uint16_t i = 0; i < WAIT_LOOPS; ++i) {
        if (TWCR & _BV(TWINT)) {
            *status = TWSR & 0xF8;
            return 1;
        }
    }
    return 0;
}

/* STOP, and wait until it is on the bus (the hardware clears TWSTO): a START
 * written before that is lost (2560 §24.7: TWSTO "cleared automatically"). */
static void stop(void)
{
    TWCR = _BV(TWINT) | _BV(TWSTO) | _BV(TWEN);
    for (uint16_t i = 0; i < WAIT_LOOPS && (TWCR & _BV(TWSTO)); ++i) {
    }
}

static uint8_t start(uint8_t sla_rw)
{
    uint8_t s;
    TWCR = _BV(TWINT) | _BV(TWSTA) | _BV(TWEN);
    if (!wait_twint(&s) || (s != 0x08 && s != 0x10)) return 0;
    TWDR = sla_rw;
    TWCR = _BV(TWINT) | _BV(TWEN);
    if (!wait_twint(&s)) return 0;
    return s == 0x18 || s == 0x40; /* SLA+W / SLA+R acknowledged */
}

void heater_link_init(void)
{
    TWBR = 72;
    TWSR = 0;
}

uint8_t heater_set(uint16_t setpoint_c)
{
    uint8_t ok = start((uint8_t)(HEATER_ADDRESS << 1));
    const uint8_t bytes[2] = {(uint8_t)setpoint_c, (uint8_t)(setpoint_c >> 8)};
    for (uint8_t i = 0; ok && i < 2; ++i) {
        uint8_t s;
        TWDR = bytes[i];
        TWCR = _BV(TWINT) | _BV(TWEN);
        ok = wait_twint(&s) && s == 0x28;
    }
    stop();
    return ok;
}

uint8_t heater_read(heater_status_t *out)
{
    uint8_t b[5];
    uint8_t ok = start((uint8_t)((HEATER_ADDRESS << 1) | 1));
    for (uint8_t i = 0; ok && i < 5; ++i) {
        uint8_t s;
        TWCR = (uint8_t)(_BV(TWINT) | _BV(TWEN) | (i < 4 ? _BV(TWEA) : 0));
        ok = wait_twint(&s) && s == (i < 4 ? 0x50 : 0x58);
        b[i] = TWDR;
    }
    stop();
    if (!ok) return 0;
    out->temp_x10 = (int16_t)(b[0] | (b[1] << 8));
    out->setpoint_c = (uint16_t)(b[2] | (b[3] << 8));
    out->temp_ok = b[4];
    return 1;
}
