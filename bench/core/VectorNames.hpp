// Interrupt vector names by MCU type, as avr-libc names them (TIMER1_COMPA
// is vector 11 of an ATmega328P): read from avr-libc's headers when the
// build is configured (bench/CMakeLists.txt).
#pragma once

#include <optional>
#include <string>

namespace avrbench {

// "" when the type or the vector is unknown.
std::string vector_name(const std::string& mcu_type, int vector);
// The vector of a name ("TIMER1_COMPA" or "TIMER1_COMPA_vect"), if the type has it.
std::optional<int> vector_number(const std::string& mcu_type, const std::string& name);
// How many vectors the type has (its last named one plus one; 0 is reset),
// if the table knows the type.
std::optional<int> vector_count(const std::string& mcu_type);

}  // namespace avrbench
