// Klipper's timer idiom (firmware/conformance/peripherals/timer_dispatch): a
// compare match whose flag is set while the NOP of `sei; nop; cli` runs is
// served before the CLI. ATmega328P §7.7 / ATmega2560 §7.8 / ATmega32
// "Interrupt Response Time": "the instruction following SEI will be executed
// before any pending interrupts" - one instruction, after which a pending
// enabled interrupt is served. simavr 1.6 waits two, so the CLI came first
// and the match stayed pending until another interrupt was raised with I = 0
// (Klipper: "Rescheduled timer in the past" 0.4 s after every reset).
#include <gtest/gtest.h>

#include <cstdint>

#include "mcu/Mcu.hpp"
#include "periph/usart/Uart.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

std::uint32_t read_u32(const Mcu& mcu, const char* symbol) {
    const auto b = mcu.read_ram(symbol, 4);
    return b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<std::uint32_t>(b[3]) << 24);
}

// How late a dispatch may start after its due time, counted by hand from the
// listing (timer_dispatch.lst) and the datasheet:
//   the longest stretch with I = 0 outside the dispatcher: the UDRE ISR, 40
//     cycles from its vector to RETI included on the 328P (prologue 9
//     instructions, 2 loads and stores, the UDRIE test, epilogue, RETI 4);
//     the main line's `cli` ... `sei` stretch with the TOV1 branch, 9 cycles;
//   + one instruction in progress when the flag is set (at most 4: a CALL/RET
//     is not in that stretch; LDS/STS 2, RETI 4);
//   + the interrupt response, 4 cycles (2560: 5), and the vector's JMP, 3;
//   + the dispatcher's own prologue until it reads TCNT1: 20 instructions,
//     28 cycles (2560: 32, RAMPZ/EIND saved too).
// 40 + 9 + 4 + 5 + 3 + 32 = 93 cycles; rounded up to 100. A match left
// pending until the next interrupt raised with I = 0 (the next TOV1, every
// 65536 cycles, or the next serial burst, every 64 dispatches) is thousands
// of cycles late.
constexpr std::uint16_t kMaxLateCycles = 100;

void expect_every_match_served_on_time(const std::string& firmware) {
    Mcu mcu(ElfImage::load(test::firmware(firmware)));
    // 50 ms: 800 000 cycles, 800 dispatches 1000 cycles apart (PERIOD).
    constexpr Cycle kRunCycles = 800'000;
    mcu.run_until(kRunCycles);
    ASSERT_EQ(mcu.read_ram_u8("started"), 1) << firmware;
    const std::uint32_t served = read_u32(mcu, "served");
    // The timer started a few dozen cycles after reset (the USART set-up):
    // 799 or 800 due times have passed, every one dispatched.
    EXPECT_GE(served, 799u) << firmware << ": due times not dispatched";
    EXPECT_LE(served, 800u) << firmware;
    EXPECT_LE(mcu.read_ram_u16("max_late"), kMaxLateCycles) << firmware << ": a dispatch started this many cycles late";
    // The main line saw every TOV1 (12 in 800 000 cycles) and the serial
    // port sent its bursts: 4 bytes per 64 dispatches.
    EXPECT_EQ(mcu.read_ram_u16("wraps"), kRunCycles / 65536) << firmware;
    EXPECT_GE(mcu.read_ram_u16("sent"), 4u * (799u / 64u) - 4u) << firmware;
}

TEST(TimerDispatch, MatchDuringTheNopAfterSeiIsServedAtmega328p) { expect_every_match_served_on_time("timer_dispatch"); }
TEST(TimerDispatch, MatchDuringTheNopAfterSeiIsServedAtmega2560) { expect_every_match_served_on_time("timer_dispatch_m2560"); }
TEST(TimerDispatch, MatchDuringTheNopAfterSeiIsServedAtmega32) { expect_every_match_served_on_time("timer_dispatch_m32"); }

}  // namespace
}  // namespace avrbench
