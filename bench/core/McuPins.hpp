// Which port pins a part actually has. simavr models every port as 8 bits, so
// without this table PD9 would be caught but PC7 on an ATmega328P would not.
#pragma once

#include <string>

namespace avrbench {

// True when `mcu_type` has pin P<port><bit>. For MCU types the table does not
// know, every bit 0..7 of a port counts (simavr decides whether the port exists).
bool mcu_has_pin(const std::string& mcu_type, char port, int bit);

// True when the table knows the MCU type's pin-out.
bool mcu_pinout_known(const std::string& mcu_type);

}  // namespace avrbench
