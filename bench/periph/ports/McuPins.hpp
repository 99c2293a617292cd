// Which port pins a part actually has. simavr models every port as 8 bits, so
// without this table PD9 would be caught but PC7 on an ATmega328P would not.
#pragma once

#include <optional>
#include <string>

namespace avrbench {

// True when `mcu_type` has pin P<port><bit>. For MCU types the table does not
// know, every bit 0..7 of a port counts (simavr decides whether the port exists).
bool mcu_has_pin(const std::string& mcu_type, char port, int bit);

// True when the table knows the MCU type's pin-out.
bool mcu_pinout_known(const std::string& mcu_type);

// The pins of USART `index`: TxDn and RxDn (each port letter and bit).
struct UsartPins {
    char tx_port;
    int tx_bit;
    char rx_port;
    int rx_bit;
};
// From the datasheets' alternate port functions (ATmega328P Table 14-9: PD1
// TXD, PD0 RXD; ATmega2560 §13.3: USART0 PE1/PE0, USART1 PD3/PD2, USART2
// PH1/PH0, USART3 PJ1/PJ0; ATmega32/644/1284: PD1/PD0, USART1 PD3/PD2).
// std::nullopt for a USART or MCU type the table does not know.
std::optional<UsartPins> usart_pins(const std::string& mcu_type, int index);

// The SPI pins: SCK, MOSI, MISO and SS (each as "PB5").
struct SpiPins {
    std::string sck, mosi, miso, ss;
};
// From the datasheets' alternate port functions (ATmega328P Table 14-3: SS
// PB2, MOSI PB3, MISO PB4, SCK PB5; ATmega2560 Table 13-6: SS PB0, SCK PB1,
// MOSI PB2, MISO PB3; ATmega16/32/164..1284: SS PB4, MOSI PB5, MISO PB6,
// SCK PB7). std::nullopt for an MCU type the table does not know.
std::optional<SpiPins> spi_pins(const std::string& mcu_type);

// True when a level change on P<port><bit> can start an interrupt through a
// peripheral other than INTn, PCINTn and the analog comparator's multiplexer
// (which Mcu::pin_change_may_interrupt reads from the MCU's registers): an
// input capture pin, a timer's external clock, a USART's RxD or XCK, the SPI
// slave's pins, TWI, the asynchronous timer's crystal, the comparator's
// AIN0/AIN1. From the datasheets' alternate port function tables (ATmega328P
// §14.3, ATmega2560 §13.3, ATmega32 "Alternate Port Functions", ATmega644/1284
// §13.3). True for every pin of an MCU type the table does not know.
bool pin_may_feed_an_interrupt(const std::string& mcu_type, char port, int bit);

}  // namespace avrbench
