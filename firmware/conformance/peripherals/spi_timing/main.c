// SPI master transfer time and write collision (ATmega328P §19.5: SCK =
// f_osc/4, 16, 64, 128 by SPR1:0, doubled by SPI2X, Table 19-5; a byte is 8
// SCK periods; §19.5.2 SPSR: "The WCOL bit is set if the SPI Data Register
// (SPDR) is written during a data transfer"; ATmega2560 §21, Table 21-5,
// §21.2.2 the same).
//
// cycles[i]: Timer1 (clk/1) cycles from the SPDR write to the poll loop
// seeing SPIF, for f/4, f/16, f/64, f/128 and f/2 (SPI2X with f/4). The
// loop's own cycles are the same for each, so differences are 8 SCK periods.
// wcol_spsr: SPSR read after writing SPDR twice in a row (WCOL is bit 6).
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "../common/periph.h"

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t cycles[5];
volatile uint8_t wcol_spsr;
volatile uint8_t done;

static uint16_t transfer_cycles(uint8_t spcr, uint8_t spsr) {
    SPCR = spcr;
    SPSR = spsr;
    const uint16_t t0 = TCNT1;
    SPDR = 0xA5;
    while (!(SPSR & (1 << SPIF))) {
    }
    const uint16_t t1 = TCNT1;
    (void)SPDR;
    return (uint16_t)(t1 - t0);
}

int main(void) {
    // SS an output (so the SPI stays master), SCK and MOSI outputs.
    SPI_DDR |= (1 << SPI_SS) | (1 << SPI_SCK) | (1 << SPI_MOSI);
    TCCR1B = (1 << CS10);
    const uint8_t master = (1 << SPE) | (1 << MSTR);
    cycles[0] = transfer_cycles(master, 0);
    cycles[1] = transfer_cycles(master | (1 << SPR0), 0);
    cycles[2] = transfer_cycles(master | (1 << SPR1), 0);
    cycles[3] = transfer_cycles(master | (1 << SPR1) | (1 << SPR0), 0);
    cycles[4] = transfer_cycles(master, 1 << SPI2X);

    SPCR = master | (1 << SPR1) | (1 << SPR0);      // f/128: a long transfer
    SPSR = 0;
    SPDR = 0x11;
    SPDR = 0x22;                                    // during the transfer
    wcol_spsr = SPSR;
    while (!(SPSR & (1 << SPIF))) {
    }
    (void)SPDR;
    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
