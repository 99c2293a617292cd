// The firmware built for several parts is named <name><suffix>
// (firmware/conformance/*/CMakeLists.txt): "" for the ATmega328P, "_m2560"
// for the ATmega2560, "_m32" for the ATmega32.
#pragma once

#include <stdexcept>
#include <string>

namespace avrbench::test {

inline std::string firmware_suffix(const std::string& mcu_type) {
    if (mcu_type == "atmega328p") return "";
    if (mcu_type == "atmega2560") return "_m2560";
    if (mcu_type == "atmega32") return "_m32";
    throw std::invalid_argument("no firmware suffix for " + mcu_type);
}

}  // namespace avrbench::test
