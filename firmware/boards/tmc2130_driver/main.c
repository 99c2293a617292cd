// A TMC2130 on the Einsy RAMBo's X driver, set up and used the way its
// datasheet describes (TMC2130 datasheet Rev. 1.09: §4.1 the 40-bit
// datagram, §4.3 SPI mode 3, §5 the registers, §8 stallGuard2), for the
// tmc2130 part's tests (tests/boards/test_tmc2130.cpp).
//
// Pins (Prusa-Firmware pins_Einsy_1_0.h, Arduino Mega numbering): X_TMC2130_CS
// 41 = PG0, X_STEP 37 = PC0, X_DIR 49 = PL0, X_ENABLE 29 = PA7, X_TMC2130_DIAG
// 64 = PK2. SPI on PB1 (SCK), PB2 (MOSI), PB3 (MISO); PB0 (SS) an output so
// the master stays master.
//
// Builds:
//  - default: read GSTAT (reset flag), write and read back CHOPCONF, read
//    IOIN, then 160 STEP pulses at 1/16, 80 pulses with dedge (160 edges) at
//    1/16, 10 pulses at full steps: 3 x 10 full steps forward.
//  - STEP_BEFORE_INIT: 10 STEP pulses before CHOPCONF is written (toff = 0).
//  - STALL_HOME: sensorless homing towards X = 0: stallGuard on DIAG1
//    (push-pull), TCOOLTHRS 1000, SGT from SGT_VALUE; a full step about
//    every 1 ms, 16 microsteps 62.5 us apart (TSTEP, in 1/256 steps of the
//    12 MHz clock: 62.5 us * 12 MHz / 16 = 47 <= 1000), until DIAG1 goes high.
//  - SPI_MODE0_FAST: the same datagrams in SPI mode 0 at f/2 = 8 MHz.
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#ifndef SGT_VALUE
#define SGT_VALUE 0
#endif

enum {
    GCONF = 0x00, GSTAT = 0x01, IOIN = 0x04, IHOLD_IRUN = 0x10, TCOOLTHRS = 0x14,
    CHOPCONF = 0x6C, COOLCONF = 0x6D, DRV_STATUS = 0x6F,
};

volatile uint8_t status_first;        // SPI_STATUS of the first datagram after power-up
volatile uint32_t gstat_read;         // GSTAT's data
volatile uint8_t status_after_gstat;  // SPI_STATUS once GSTAT was read
volatile uint32_t chopconf_read;      // CHOPCONF as read back
volatile uint32_t ioin_read;
volatile uint32_t drv_status_read;
volatile uint16_t steps_to_stall;     // STALL_HOME: full steps until DIAG1 rose
volatile uint8_t done;

static uint8_t spi(uint8_t b) {
    SPDR = b;
    while (!(SPSR & (1 << SPIF))) {
    }
    return SPDR;
}

// One datagram: the SPI_STATUS byte back, the 32 data bits in *reply.
static uint8_t datagram(uint8_t address, uint32_t data, uint32_t* reply) {
    PORTG &= (uint8_t)~(1 << PG0);
    const uint8_t status = spi(address);
    uint32_t r = 0;
    for (int8_t i = 3; i >= 0; --i) r = (r << 8) | spi((uint8_t)(data >> (8 * i)));
    PORTG |= (1 << PG0);
    if (reply) *reply = r;
    return status;
}

static void write_reg(uint8_t address, uint32_t value) { datagram(address | 0x80, value, 0); }

// A read is answered by the next datagram (§4.1.1): ask twice.
static uint32_t read_reg(uint8_t address, uint8_t* status) {
    uint32_t r;
    datagram(address, 0, 0);
    const uint8_t s = datagram(address, 0, &r);
    if (status) *status = s;
    return r;
}

__attribute__((unused)) static void pulses(uint16_t n) {
    for (uint16_t i = 0; i < n; ++i) {
        PORTC |= (1 << PC0);
        _delay_us(5);
        PORTC &= (uint8_t)~(1 << PC0);
        _delay_us(5);
    }
}

int main(void) {
    DDRB |= (1 << PB0) | (1 << PB1) | (1 << PB2);  // SS, SCK, MOSI out
    DDRG |= (1 << PG0);
    PORTG |= (1 << PG0);                           // CS idle high
    DDRC |= (1 << PC0);
    DDRL |= (1 << PL0);
    DDRA |= (1 << PA7);
    PORTA |= (1 << PA7);                           // ENN high: off until set up
#ifdef SPI_MODE0_FAST
    SPCR = (1 << SPE) | (1 << MSTR);               // mode 0, f/4
    SPSR = (1 << SPI2X);                           // f/2 = 8 MHz
#else
    SPCR = (1 << SPE) | (1 << MSTR) | (1 << CPOL) | (1 << CPHA) | (1 << SPR0);  // mode 3, f/16 = 1 MHz
#endif
    PORTL |= (1 << PL0);                           // DIR high: forward

#ifdef STEP_BEFORE_INIT
    PORTA &= (uint8_t)~(1 << PA7);
    pulses(10);
#endif
    status_first = datagram(GSTAT, 0, 0);          // asks for GSTAT
    uint32_t gstat;
    datagram(GSTAT, 0, &gstat);                    // GSTAT's data comes with the next one
    gstat_read = gstat;
    status_after_gstat = datagram(GSTAT, 0, 0);

    write_reg(CHOPCONF, 0x04000003UL);             // MRES 4 (1/16), toff 3
    write_reg(IHOLD_IRUN, 0x00001008UL);           // IRUN 16, IHOLD 8
    chopconf_read = read_reg(CHOPCONF, 0);
    ioin_read = read_reg(IOIN, 0);
    PORTA &= (uint8_t)~(1 << PA7);                 // ENN low: on

#ifdef STALL_HOME
    write_reg(TCOOLTHRS, 1000);
    write_reg(COOLCONF, ((uint32_t)(SGT_VALUE & 0x7F)) << 16);
    write_reg(GCONF, 0x00003100UL);                // diag1_stall, diag0/diag1 push-pull
    PORTL &= (uint8_t)~(1 << PL0);                 // DIR low: towards 0
    uint16_t steps = 0;
    while (!(PINK & (1 << PK2)) && steps < 2000) {
        for (uint8_t m = 0; m < 16; ++m) {         // one full step: 16 microsteps, 1 ms
            PORTC |= (1 << PC0);
            _delay_us(5);
            PORTC &= (uint8_t)~(1 << PC0);
            _delay_us(57);
            if (PINK & (1 << PK2)) break;
        }
        ++steps;
    }
    steps_to_stall = steps;
    drv_status_read = read_reg(DRV_STATUS, 0);
#else
    pulses(160);                                   // 160 microsteps at 1/16: 10 full steps
    write_reg(CHOPCONF, 0x24000003UL);             // + dedge
    pulses(80);                                    // 160 edges: 10 full steps
    write_reg(CHOPCONF, 0x08000003UL);             // MRES 8: full steps, no dedge
    pulses(10);                                    // 10 full steps
    drv_status_read = read_reg(DRV_STATUS, 0);
#endif
    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
