/*
 * twi_pair - the TWI (I2C) between two AVRs, register by register, against
 * the datasheet's status tables (ATmega328P §22.7 Tables 22-2 master
 * transmitter, 22-3 master receiver, 22-4 slave receiver, 22-5 slave
 * transmitter; ATmega2560 §24.7; ATmega32 §22.7). Built twice: the master
 * (polling TWINT) and, with TWI_SLAVE, the slave at address 0x10 (TWI_vect).
 * The board joining them is in tests/conformance_periph/test_twi_pair.cpp.
 *
 * Master, SCL = 16 MHz / (16 + 2 * 72) = 100 kHz (§22.5.2):
 *   0  TWDR written while TWINT = 0 -> TWWC set (§22.9.2)
 *   1  START, SLA+W to 0x50 (nobody)            08 20, STOP
 *      cycles_addr_nack: the SLA+W byte, 9 SCL periods = 1440 cycles
 *   2  START, SLA+W 0x10, A1, B2, C3            08 18 28 28 30, STOP
 *      the slave stretches SCL for 100 us after its address (it has
 *      TWINT set): cycles_stretched = 1600 + 1440 cycles and a little
 *      the slave NACKs C3 (it cleared TWEA after two bytes)
 *   3  START, SLA+W, 01, repeated START, SLA+R, read ACK, read NACK
 *                                               08 18 28 10 40 50 58, STOP
 *   4  START, general call (address 0), 5A      08 18 28, STOP
 * Slave (TWAR = 0x10 << 1 | TWGCE):
 *   2  60 80 80 88      (not addressed after 88: the STOP gives no A0)
 *   3  60 80 A0 A8 B8 C0 (A0 for the repeated START; not addressed after C0)
 *   4  70 90 A0
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#define SLAVE_ADDRESS 0x10

#ifndef TWI_SLAVE

volatile uint8_t status_log[24];
volatile uint8_t status_count;
volatile uint16_t cycles_addr_nack;
volatile uint16_t cycles_stretched;
volatile uint8_t read_back[2];
volatile uint8_t twwc_seen;
volatile uint8_t done;

static uint8_t wait_twint(void)
{
    while (!(TWCR & _BV(TWINT))) {
    }
    uint8_t s = TWSR & 0xF8;
    status_log[status_count++] = s;
    return s;
}

static void go(uint8_t extra_bits)
{
    TWCR = _BV(TWINT) | _BV(TWEN) | extra_bits;
}

static void stop(void)
{
    TWCR = _BV(TWINT) | _BV(TWEN) | _BV(TWSTO);
    while (TWCR & _BV(TWSTO)) {
    }
}

int main(void)
{
    TWBR = 72;
    TWSR = 0;
    TCCR1A = 0;
    TCCR1B = _BV(CS10);
    _delay_us(50); /* the slave sets up its address */

    TWCR = _BV(TWEN);
    TWDR = 0x55;
    twwc_seen = (TWCR & _BV(TWWC)) ? 1 : 0;

    uint16_t t0;
    go(_BV(TWSTA));
    wait_twint();
    TWDR = 0x50 << 1;
    t0 = TCNT1;
    go(0);
    wait_twint();
    cycles_addr_nack = TCNT1 - t0;
    stop();

    go(_BV(TWSTA));
    wait_twint();
    TWDR = SLAVE_ADDRESS << 1;
    go(0);
    wait_twint();
    TWDR = 0xA1;
    t0 = TCNT1;
    go(0);
    wait_twint();
    cycles_stretched = TCNT1 - t0;
    TWDR = 0xB2;
    go(0);
    wait_twint();
    TWDR = 0xC3;
    go(0);
    wait_twint();
    stop();

    go(_BV(TWSTA));
    wait_twint();
    TWDR = SLAVE_ADDRESS << 1;
    go(0);
    wait_twint();
    TWDR = 0x01;
    go(0);
    wait_twint();
    go(_BV(TWSTA));
    wait_twint();
    TWDR = (SLAVE_ADDRESS << 1) | 1;
    go(0);
    wait_twint();
    go(_BV(TWEA));
    wait_twint();
    read_back[0] = TWDR;
    go(0);
    wait_twint();
    read_back[1] = TWDR;
    stop();

    go(_BV(TWSTA));
    wait_twint();
    TWDR = 0x00;
    go(0);
    wait_twint();
    TWDR = 0x5A;
    go(0);
    wait_twint();
    stop();

    done = 1;
    for (;;) {
    }
}

#else /* TWI_SLAVE */

static const uint8_t table[4] = {0x11, 0x22, 0x33, 0x44};
volatile uint8_t slave_log[24];
volatile uint8_t slave_count;
volatile uint8_t received[8];
volatile uint8_t received_count;
volatile uint8_t nacked_byte;
volatile uint8_t general_call_byte;
static uint8_t pointer;
static uint8_t bytes_in_transfer;
static uint8_t stretched;

ISR(TWI_vect)
{
    uint8_t s = TWSR & 0xF8;
    uint8_t ack = _BV(TWEA);
    if (slave_count < sizeof slave_log) slave_log[slave_count++] = s;
    switch (s) {
    case 0x60:
        bytes_in_transfer = 0;
        if (!stretched) {
            stretched = 1;
            _delay_us(100); /* SCL stays low while TWINT is set */
        }
        break;
    case 0x80: {
        uint8_t b = TWDR;
        received[received_count++] = b;
        if (bytes_in_transfer == 0) pointer = b;
        if (++bytes_in_transfer >= 2) ack = 0;
        break;
    }
    case 0x88:
        nacked_byte = TWDR;
        break;
    case 0x90:
        general_call_byte = TWDR;
        break;
    case 0xA8:
    case 0xB8:
        TWDR = table[pointer & 3];
        pointer++;
        break;
    default:
        break;
    }
    TWCR = _BV(TWINT) | _BV(TWEN) | _BV(TWIE) | ack;
}

int main(void)
{
    TWAR = (SLAVE_ADDRESS << 1) | _BV(TWGCE);
    TWCR = _BV(TWEA) | _BV(TWEN) | _BV(TWIE);
    sei();
    for (;;) {
    }
}

#endif
