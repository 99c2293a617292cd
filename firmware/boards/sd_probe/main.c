// An SD card in the Einsy RAMBo's slot (SDSS 77 = PJ6, SDCARDDETECT 15 =
// PJ0, per Prusa-Firmware pins_Einsy_1_0.h and fastio.h) brought up in SPI
// mode the way the SD Physical Layer Simplified Specification (§7.2.1, Figure
// 7-2) and Arduino's Sd2Card (Marlin, Prusa-Firmware) do it, for the sd_card
// part's tests (tests/boards/test_sd_card.cpp): 80 clocks with CS high,
// CMD0, CMD8, CMD55 + ACMD41 until ready, CMD58, CMD9; then block 0 read,
// block 1 written and read back.
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t card_detect;      // PJ0 with the pull-up on: 0 = a card in
volatile uint8_t r1_cmd0;
volatile uint8_t r7[5];            // CMD8: R1 and the 4 bytes echoed
volatile uint16_t acmd41_tries;
volatile uint8_t ocr[5];           // CMD58: R1 and the OCR
volatile uint8_t csd[16];
volatile uint8_t block0_head[4];
volatile uint8_t block0_tail[2];   // bytes 510, 511
volatile uint8_t write_response;   // the data response token, low 5 bits
volatile uint8_t block1_head[4];
volatile uint8_t done;

static uint8_t spi(uint8_t b) {
    SPDR = b;
    while (!(SPSR & (1 << SPIF))) {
    }
    return SPDR;
}
static void select(void) { PORTJ &= (uint8_t)~(1 << PJ6); }
static void deselect(void) { PORTJ |= (1 << PJ6); spi(0xFF); }

// A command and its R1 (the first byte that is not 0xFF, within 8 bytes).
static uint8_t command(uint8_t index, uint32_t arg, uint8_t crc) {
    spi(0xFF);
    spi(0x40 | index);
    spi((uint8_t)(arg >> 24));
    spi((uint8_t)(arg >> 16));
    spi((uint8_t)(arg >> 8));
    spi((uint8_t)arg);
    spi(crc);
    uint8_t r = 0xFF;
    for (uint8_t i = 0; i < 8 && (r = spi(0xFF)) == 0xFF; ++i) {
    }
    return r;
}

static uint8_t wait_token(void) {
    uint8_t t = 0xFF;
    for (uint16_t i = 0; i < 1000 && (t = spi(0xFF)) == 0xFF; ++i) {
    }
    return t;
}

int main(void) {
    DDRB |= (1 << PB0) | (1 << PB1) | (1 << PB2);  // SS, SCK, MOSI out
    DDRJ |= (1 << PJ6);
    PORTJ |= (1 << PJ6) | (1 << PJ0);              // CS high; pull-up on the detect input
    SPCR = (1 << SPE) | (1 << MSTR) | (1 << SPR1) | (1 << SPR0);  // f/128 = 125 kHz (<= 400 kHz to init)
    _delay_us(10);
    card_detect = PINJ & (1 << PJ0);
    for (uint8_t i = 0; i < 10; ++i) spi(0xFF);    // >= 74 clocks with CS high

    select();
    r1_cmd0 = command(0, 0, 0x95);
    r7[0] = command(8, 0x1AA, 0x87);
    for (uint8_t i = 1; i < 5; ++i) r7[i] = spi(0xFF);
    uint16_t tries = 0;
    uint8_t r;
    do {
        command(55, 0, 0x01);
        r = command(41, 0x40000000UL, 0x01);       // HCS: a host that knows SDHC
        ++tries;
        _delay_us(500);
    } while (r != 0 && tries < 1000);
    acmd41_tries = tries;
    ocr[0] = command(58, 0, 0x01);
    for (uint8_t i = 1; i < 5; ++i) ocr[i] = spi(0xFF);
    SPCR = (1 << SPE) | (1 << MSTR);               // f/4 once initialised
    SPSR = (1 << SPI2X);                           // f/2 = 8 MHz
    if (command(9, 0, 0x01) == 0 && wait_token() == 0xFE) {
        for (uint8_t i = 0; i < 16; ++i) csd[i] = spi(0xFF);
        spi(0xFF);
        spi(0xFF);
    }
    // Block 0 (block addresses: the card said SDHC in the OCR).
    const uint8_t sdhc = (ocr[1] & 0x40) != 0;
    if (command(17, 0, 0x01) == 0 && wait_token() == 0xFE) {
        for (uint16_t i = 0; i < 512; ++i) {
            const uint8_t b = spi(0xFF);
            if (i < 4) block0_head[i] = b;
            if (i >= 510) block0_tail[i - 510] = b;
        }
        spi(0xFF);
        spi(0xFF);
    }
    // Block 1: "AVRB" then zeros.
    const uint32_t block1 = sdhc ? 1 : 512;
    if (command(24, block1, 0x01) == 0) {
        spi(0xFF);
        spi(0xFE);
        for (uint16_t i = 0; i < 512; ++i) spi(i < 4 ? (uint8_t)"AVRB"[i] : 0);
        spi(0xFF);                                 // CRC16, not checked (CMD59 not sent)
        spi(0xFF);
        write_response = spi(0xFF) & 0x1F;
        while (spi(0xFF) == 0x00) {                // busy while programming
        }
    }
    if (command(17, block1, 0x01) == 0 && wait_token() == 0xFE) {
        for (uint16_t i = 0; i < 512; ++i) {
            const uint8_t b = spi(0xFF);
            if (i < 4) block1_head[i] = b;
        }
        spi(0xFF);
        spi(0xFF);
    }
    deselect();
    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
