// Vector names from avr-libc's headers (bench/CMakeLists.txt reads them
// through avr-gcc when the build is configured).
#include <gtest/gtest.h>

#include "core/VectorNames.hpp"

namespace avrbench {
namespace {

TEST(VectorNames, AreAvrLibcsPerMcuType) {
    // ATmega328P datasheet, "Interrupts" table: TIMER1 COMPA is program
    // address 0x0016 (word), vector 11 counting the reset as 0; on the
    // ATmega2560 it is 0x0022, vector 17.
    EXPECT_EQ(vector_name("atmega328p", 11), "TIMER1_COMPA");
    EXPECT_EQ(vector_name("atmega2560", 17), "TIMER1_COMPA");
    EXPECT_EQ(vector_number("atmega328p", "TIMER1_COMPA"), 11);
    EXPECT_EQ(vector_number("atmega328p", "TIMER1_COMPA_vect"), 11);
    EXPECT_EQ(vector_number("atmega2560", "USART1_RX"), 36);  // ATmega2560 table: 0x0048 / 2
    EXPECT_FALSE(vector_number("atmega328p", "USART1_RX").has_value());  // one USART on the 328P
    EXPECT_EQ(vector_name("atmega328p", 99), "");
}

}  // namespace
}  // namespace avrbench
