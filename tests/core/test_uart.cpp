// USART0 of uart_echo: 115200 baud with U2X0 = 1, UBRR0 = 16, 8N1.
// ATmega328P §19.3.1 table 19-1: baud = f / (8 (UBRR + 1)) with U2X, so one bit
// is 8 * (16 + 1) = 136 cycles; §19.4: an 8N1 frame is 1 start + 8 data +
// 1 stop = 10 bits = 1360 cycles (85 us at 16 MHz).
#include <gtest/gtest.h>

extern "C" {
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_io.h>
}

#include "mcu/ElfImage.hpp"
#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

constexpr Cycle kCyclesPerBit = 8 * (16 + 1);
constexpr Cycle kCyclesPerFrame = 10 * kCyclesPerBit;  // 1360

TEST(Uart, FrameIsTenBitTimesAt115200WithU2x) {
    Mcu mcu(ElfImage::load(test::firmware("uart_echo")));
    Uart& uart = mcu.uart(0);
    mcu.run_for(16000 * 5);  // 5 ms: the 20-byte banner takes 20 * 85 us = 1.7 ms
    ASSERT_EQ(uart.transmitted_text(), "avrbench uart_echo\r\n");
    EXPECT_EQ(uart.cycles_per_frame(), kCyclesPerFrame);

    // The banner is written by polling UDRE0. The transmitter is double
    // buffered (§20.6, periph/usart/UartTransmitter): the next byte waits in UDR
    // while a frame is shifted out and follows its stop bit at once, so bytes
    // leave exactly one frame apart (each stamped at its start bit). A frame
    // of 11 bit times (simavr 1.6's parity-always count) would give 1496.
    const auto& bytes = uart.transmitted();
    for (std::size_t i = 1; i < bytes.size(); ++i) {
        EXPECT_EQ(bytes[i].cycle - bytes[i - 1].cycle, kCyclesPerFrame) << "byte " << i;
    }
}

TEST(Uart, SpeedBitsWrittenAfterUbrrStillCount) {
    // uart_echo_speed_last writes UBRR0 before U2X0 and UCSZ0; the datasheet
    // frame is the same 1360 cycles (simavr 1.6 alone keeps the byte time it
    // computed at the UBRR0L write, with U2X0 still 0).
    Mcu mcu(ElfImage::load(test::firmware("uart_echo_speed_last")));
    Uart& uart = mcu.uart(0);
    mcu.run_for(16000 * 5);
    ASSERT_EQ(uart.transmitted_text(), "avrbench uart_echo\r\n");
    EXPECT_EQ(uart.cycles_per_frame(), kCyclesPerFrame);
    const auto& bytes = uart.transmitted();
    for (std::size_t i = 1; i < bytes.size(); ++i) {
        EXPECT_EQ(bytes[i].cycle - bytes[i - 1].cycle, kCyclesPerFrame) << "byte " << i;  // §20.6, as above
    }
}

TEST(Uart, PollingNeverSleepsOnTheWallClock) {
    // simavr's UART usleep(1)s on every UCSRnA read while idle
    // (AVR_UART_FLAG_POLL_SLEEP, on by default) and echoes output lines to
    // stdout (AVR_UART_FLAG_STDIO); the bench clears both.
    Mcu mcu(ElfImage::load(test::firmware("uart_echo")));
    std::uint32_t flags = 0xffffffff;
    ASSERT_EQ(mcu.ioctl(AVR_IOCTL_UART_GET_FLAGS('0'), &flags), 0);
    EXPECT_EQ(flags & (AVR_UART_FLAG_POLL_SLEEP | AVR_UART_FLAG_STDIO), 0u);
}

TEST(Uart, EchoesWhatTheHostSends) {
    Mcu mcu(ElfImage::load(test::firmware("uart_echo")));
    Uart& uart = mcu.uart(0);
    uart.send("G1 X10\n");
    mcu.run_for(16000 * 10);
    EXPECT_EQ(uart.transmitted_text(), "avrbench uart_echo\r\nG1 X10\n");
    EXPECT_EQ(uart.bytes_delivered(), 7u);
}

TEST(Uart, McuWithoutThatUsartIsAClearError) {
    Mcu mcu(ElfImage::load(test::firmware("uart_echo")));
    EXPECT_THROW(mcu.uart(3), BadInput);  // the 328P has USART0 only
}

}  // namespace
}  // namespace avrbench
