// The SS pin of an SPI master (ATmega328P §19.3.2 "SS Pin Functionality",
// Master Mode; ATmega2560 §21.3.2 the same): "If SS is configured as an
// input, it must be held high to ensure Master SPI operation. If the SS pin
// is driven low by peripheral circuitry when the SPI is configured as a
// Master with the SS pin defined as an input, ... 1. The MSTR bit in SPCR is
// cleared and the SPI system becomes a Slave. ... 2. The SPIF Flag in SPSR
// is set, and if the SPI interrupt is enabled, and the I-bit in SREG is set,
// the interrupt routine will be executed." "When SS is configured as an
// output, the pin is a general output pin which does not affect the SPI
// system."
//
// stage 1: SS an input held high by its pull-up: a byte goes out, MSTR stays.
// stage 2: SS an output driven low: a byte goes out, MSTR stays.
// stage 3: SS an input without pull-up, driven high by the test: master
//          again; the test drives it low: MSTR cleared, SPIF set (polled).
// stage 4: recorded. stage 5: SS driven high again, master with SPIE and I
//          set; the test drives SS low: the interrupt runs once, MSTR cleared.
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "../common/periph.h"

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t stage;
volatile uint8_t spcr_input_high, spsr_input_high;
volatile uint8_t spcr_output_low, spsr_output_low;
volatile uint8_t spcr_driven_low, spsr_driven_low;
volatile uint8_t spcr_in_isr, isr_count, spcr_after_isr;
volatile uint8_t done;

ISR(SPI_STC_vect) {
    spcr_in_isr = SPCR;
    ++isr_count;
}

static uint8_t send_byte(void) {
    SPDR = 0x5A;
    for (uint16_t i = 0; i < 1000 && !(SPSR & (1 << SPIF)); ++i) {
    }
    const uint8_t spsr = SPSR;
    (void)SPDR;
    return spsr;
}

int main(void) {
    SPI_DDR |= (1 << SPI_SCK) | (1 << SPI_MOSI);
    const uint8_t master = (1 << SPE) | (1 << MSTR);

    SPI_DDR &= (uint8_t)~(1 << SPI_SS);
    PORTB |= (1 << SPI_SS);                         // pull-up: held high
    SPCR = master;
    spsr_input_high = send_byte();
    spcr_input_high = SPCR;
    stage = 1;

    SPI_DDR |= (1 << SPI_SS);
    PORTB &= (uint8_t)~(1 << SPI_SS);               // an output, low
    SPCR = master;
    spsr_output_low = send_byte();
    spcr_output_low = SPCR;
    stage = 2;

    SPI_DDR &= (uint8_t)~(1 << SPI_SS);             // an input, no pull-up: the test drives it
    while (!(PINB & (1 << SPI_SS))) {               // until the test drives SS high
    }
    SPCR = master;
    stage = 3;
    for (uint16_t i = 0; i < 5000 && !(SPSR & (1 << SPIF)); ++i) {  // the test drives SS low
    }
    spsr_driven_low = SPSR;
    spcr_driven_low = SPCR;
    (void)SPDR;                                     // SPIF cleared: SPSR read with it set, then SPDR
    stage = 4;

    while (!(PINB & (1 << SPI_SS))) {               // until the test drives SS high again
    }
    SPCR = master | (1 << SPIE);
    stage = 5;
    sei();
    for (uint16_t i = 0; i < 5000 && isr_count == 0; ++i) {  // the test drives SS low
    }
    spcr_after_isr = SPCR;
    done = 1;
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) sleep_mode();
}
