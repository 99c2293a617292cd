// The Einsy RAMBo's XFLASH (a W25X20CL on the SPI bus, chip select
// XFLASH_PIN_CS 32 = PC5 per Prusa-Firmware pins_Einsy_1_0.h and fastio.h),
// used the way its datasheet's instructions (§8.2) and Prusa-Firmware's
// xflash.c use it, for the spi_flash part's tests
// (tests/boards/test_spi_flash.cpp): the JEDEC and manufacturer/device IDs, a
// sector erase timed with Timer1 (clk/64: 4 us ticks) until BUSY clears, a
// page program read back, and one program without Write Enable.
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t jedec[3];
volatile uint8_t mfr_dev[2];
volatile uint16_t erase_ticks;   // Timer1 ticks from the erase to BUSY clear
volatile uint8_t readback[6];
volatile uint8_t status_after;   // the status once all is done
volatile uint8_t done;

static uint8_t spi(uint8_t b) {
    SPDR = b;
    while (!(SPSR & (1 << SPIF))) {
    }
    return SPDR;
}
static void select(void) { PORTC &= (uint8_t)~(1 << PC5); }
static void deselect(void) { PORTC |= (1 << PC5); }
static void command(uint8_t c) { select(); spi(c); deselect(); }
static void address(uint32_t a) { spi((uint8_t)(a >> 16)); spi((uint8_t)(a >> 8)); spi((uint8_t)a); }
static uint8_t status(void) {
    select();
    spi(0x05);
    const uint8_t s = spi(0xFF);
    deselect();
    return s;
}

int main(void) {
    DDRB |= (1 << PB0) | (1 << PB1) | (1 << PB2);  // SS, SCK, MOSI out
    DDRC |= (1 << PC5);
    deselect();
    SPCR = (1 << SPE) | (1 << MSTR) | (1 << SPR0);  // mode 0, f/16
    TCCR1B = (1 << CS11) | (1 << CS10);              // Timer1 clk/64

    select();
    spi(0x9F);
    for (uint8_t i = 0; i < 3; ++i) jedec[i] = spi(0xFF);
    deselect();
    select();
    spi(0x90);
    address(0);
    mfr_dev[0] = spi(0xFF);
    mfr_dev[1] = spi(0xFF);
    deselect();

    command(0x06);                                   // write enable
    select();
    spi(0x20);                                       // 4 KB sector erase at 0x001000
    address(0x001000);
    deselect();
    const uint16_t start = TCNT1;
    while (status() & 0x01) {
    }
    erase_ticks = TCNT1 - start;

    command(0x06);
    select();
    spi(0x02);                                       // page program "Hello" at 0x001000
    address(0x001000);
    const char* hello = "Hello";
    for (uint8_t i = 0; i < 5; ++i) spi((uint8_t)hello[i]);
    deselect();
    while (status() & 0x01) {
    }
    select();
    spi(0x02);                                       // again, without write enable
    address(0x001000);
    spi(0x00);
    deselect();

    select();
    spi(0x03);                                       // read 6 bytes
    address(0x001000);
    for (uint8_t i = 0; i < 6; ++i) readback[i] = spi(0xFF);
    deselect();
    status_after = status();
    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
