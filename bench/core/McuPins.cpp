#include "core/McuPins.hpp"

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

}  // namespace avrbench
