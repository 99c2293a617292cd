#include "periph/ports/McuPins.hpp"

#include <cstdint>
#include <map>
#include <vector>

namespace avrbench {
namespace {

// Bit mask of existing pins per port letter 'A'..'L', from the datasheets'
// pin configurations.
using PortMasks = std::map<char, std::uint8_t>;

const std::map<std::string, PortMasks>& pinouts() {
    static const PortMasks kMega48_328 = {{'B', 0xFF}, {'C', 0x7F}, {'D', 0xFF}};  // ATmega328P §1: PC6 is RESET, no PC7
    static const PortMasks kMega2560 = {  // ATmega2560 §1 (100-pin): G has 6 pins
        {'A', 0xFF}, {'B', 0xFF}, {'C', 0xFF}, {'D', 0xFF}, {'E', 0xFF}, {'F', 0xFF},
        {'G', 0x3F}, {'H', 0xFF}, {'J', 0xFF}, {'K', 0xFF}, {'L', 0xFF}};
    static const PortMasks kMega32_644 = {{'A', 0xFF}, {'B', 0xFF}, {'C', 0xFF}, {'D', 0xFF}};  // 40-pin parts
    static const std::map<std::string, PortMasks> table = {
        {"atmega48", kMega48_328},   {"atmega88", kMega48_328},   {"atmega168", kMega48_328},
        {"atmega168p", kMega48_328}, {"atmega328", kMega48_328},  {"atmega328p", kMega48_328},
        {"atmega1280", kMega2560},   {"atmega2560", kMega2560},
        {"atmega16", kMega32_644},   {"atmega32", kMega32_644},   {"atmega164", kMega32_644},
        {"atmega324", kMega32_644},  {"atmega644", kMega32_644},  {"atmega1284", kMega32_644},
    };
    return table;
}

}  // namespace

bool mcu_pinout_known(const std::string& mcu_type) { return pinouts().count(mcu_type) != 0; }

bool mcu_has_pin(const std::string& mcu_type, char port, int bit) {
    if (bit < 0 || bit > 7) return false;
    auto it = pinouts().find(mcu_type);
    if (it == pinouts().end()) return true;
    auto p = it->second.find(port);
    return p != it->second.end() && (p->second & (1u << bit)) != 0;
}

std::optional<UsartPins> usart_pins(const std::string& mcu_type, int index) {
    static const std::map<std::string, std::vector<UsartPins>> table = [] {
        const std::vector<UsartPins> mega48_328 = {{'D', 1, 'D', 0}};
        const std::vector<UsartPins> mega2560 = {{'E', 1, 'E', 0}, {'D', 3, 'D', 2}, {'H', 1, 'H', 0}, {'J', 1, 'J', 0}};
        const std::vector<UsartPins> mega16_32 = {{'D', 1, 'D', 0}};
        const std::vector<UsartPins> mega164_1284 = {{'D', 1, 'D', 0}, {'D', 3, 'D', 2}};
        return std::map<std::string, std::vector<UsartPins>>{
            {"atmega48", mega48_328},    {"atmega88", mega48_328},  {"atmega168", mega48_328},
            {"atmega168p", mega48_328},  {"atmega328", mega48_328}, {"atmega328p", mega48_328},
            {"atmega1280", mega2560},    {"atmega2560", mega2560},
            {"atmega16", mega16_32},     {"atmega32", mega16_32},
            {"atmega164", mega164_1284}, {"atmega324", mega164_1284}, {"atmega644", mega164_1284},
            {"atmega1284", mega164_1284},
        };
    }();
    auto it = table.find(mcu_type);
    if (it == table.end() || index < 0 || static_cast<std::size_t>(index) >= it->second.size()) return std::nullopt;
    return it->second[static_cast<std::size_t>(index)];
}

std::optional<SpiPins> spi_pins(const std::string& mcu_type) {
    static const std::map<std::string, SpiPins> table = [] {
        const SpiPins mega48_328 = {"PB5", "PB3", "PB4", "PB2"};
        const SpiPins mega2560 = {"PB1", "PB2", "PB3", "PB0"};
        const SpiPins mega16_1284 = {"PB7", "PB5", "PB6", "PB4"};
        return std::map<std::string, SpiPins>{
            {"atmega48", mega48_328},    {"atmega88", mega48_328},   {"atmega168", mega48_328},
            {"atmega168p", mega48_328},  {"atmega328", mega48_328},  {"atmega328p", mega48_328},
            {"atmega1280", mega2560},    {"atmega2560", mega2560},
            {"atmega16", mega16_1284},   {"atmega32", mega16_1284},  {"atmega164", mega16_1284},
            {"atmega324", mega16_1284},  {"atmega644", mega16_1284}, {"atmega1284", mega16_1284},
        };
    }();
    auto it = table.find(mcu_type);
    if (it == table.end()) return std::nullopt;
    return it->second;
}

bool pin_may_feed_an_interrupt(const std::string& mcu_type, char port, int bit) {
    struct PortBit {
        char port;
        int bit;
    };
    using Pins = std::vector<PortBit>;
    static const std::map<std::string, Pins> table = [] {
        // ICP1 PB0, SS/MOSI/MISO/SCK PB2..PB5, TOSC1/2 PB6/PB7, SDA/SCL PC4/PC5,
        // RXD PD0, XCK/T0 PD4, T1 PD5, AIN0/AIN1 PD6/PD7.
        const Pins mega48_328 = {{'B', 0}, {'B', 2}, {'B', 3}, {'B', 4}, {'B', 5}, {'B', 6}, {'B', 7}, {'C', 4},
                                 {'C', 5}, {'D', 0}, {'D', 4}, {'D', 5}, {'D', 6}, {'D', 7}};
        // SS/SCK/MOSI/MISO PB0..PB3, SCL/SDA PD0/PD1, RXD1 PD2, ICP1 PD4, XCK1 PD5,
        // T1 PD6, T0 PD7, RXD0 PE0, XCK0/AIN0 PE2, AIN1 PE3, T3 PE6, ICP3 PE7,
        // TOSC2/TOSC1 PG3/PG4, RXD2 PH0, XCK2 PH2, T4 PH7, RXD3 PJ0, XCK3 PJ2,
        // ICP4/ICP5/T5 PL0..PL2.
        const Pins mega2560 = {{'B', 0}, {'B', 1}, {'B', 2}, {'B', 3}, {'D', 0}, {'D', 1}, {'D', 2}, {'D', 4},
                               {'D', 5}, {'D', 6}, {'D', 7}, {'E', 0}, {'E', 2}, {'E', 3}, {'E', 6}, {'E', 7},
                               {'G', 3}, {'G', 4}, {'H', 0}, {'H', 2}, {'H', 7}, {'J', 0}, {'J', 2}, {'L', 0},
                               {'L', 1}, {'L', 2}};
        // T0/XCK PB0, T1 PB1, AIN0 PB2, AIN1 PB3, SS/MOSI/MISO/SCK PB4..PB7,
        // SCL/SDA PC0/PC1, TOSC1/2 PC6/PC7, RXD PD0, ICP1 PD6 (the 164..1284 add
        // RXD1 PD2, XCK1 PD4, and on the 1284 ICP3/T3 on PB5/PB6, SPI pins anyway).
        const Pins mega16_1284 = {{'B', 0}, {'B', 1}, {'B', 2}, {'B', 3}, {'B', 4}, {'B', 5}, {'B', 6},
                                  {'B', 7}, {'C', 0}, {'C', 1}, {'C', 6}, {'C', 7}, {'D', 0}, {'D', 2},
                                  {'D', 4}, {'D', 6}};
        return std::map<std::string, Pins>{
            {"atmega48", mega48_328},    {"atmega88", mega48_328},    {"atmega168", mega48_328},
            {"atmega168p", mega48_328},  {"atmega328", mega48_328},   {"atmega328p", mega48_328},
            {"atmega1280", mega2560},    {"atmega2560", mega2560},
            {"atmega16", mega16_1284},   {"atmega32", mega16_1284},   {"atmega164", mega16_1284},
            {"atmega324", mega16_1284},  {"atmega644", mega16_1284},  {"atmega1284", mega16_1284},
        };
    }();
    auto it = table.find(mcu_type);
    if (it == table.end()) return true;
    for (const PortBit& p : it->second) {
        if (p.port == port && p.bit == bit) return true;
    }
    return false;
}

}  // namespace avrbench
