// Writing TCNTn (firmware/conformance/timers/tmr_tcnt_write).
//
// ATmega328P datasheet §16.7.2 "Compare Match Blocking by TCNT1 Write" (§15.5.2
// for Timer0; ATmega2560 §17.7.2; ATmega32 "Compare Match Blocking by TCNT1
// Write"): "All CPU write operations to the TCNT1 Register will block any
// compare match that occurs in the next timer clock cycle, even when the timer
// is stopped." The counter goes on from the value written (§16.9.1: "a new
// counter value can be written anytime").
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

// 1 = flag set. [0] TCNT1 = 0xFFF0 before the first start: TOV1 within 16
// clocks of the 100; [1] TCNT1 = OCR1A = 1000 written while stopped: the match
// on the first clock is blocked, and the counter has left 1000 by the next;
// [2] TCNT1 = 999: the match comes on the second clock; [3] TCNT1 = 1000
// written while running: blocked too; [4..7] the same on Timer0 (0xF0, OCR0A = 100).
void expect_blocking(const TimerPart& part) {
    Mcu mcu(timer_firmware("tmr_tcnt_write", part));
    mcu.run_for(5000);
    ASSERT_EQ(mcu.read_ram_u8("done"), 1);
    EXPECT_EQ(ram_bytes(mcu, "r", 8), (std::vector<unsigned>{1, 0, 1, 0, 1, 0, 1, 0}));
}

TEST(TimerTcntWrite, BlocksTheNextCompareMatchAndIsKeptWhileStoppedAtmega328p) { expect_blocking(kAtmega328p); }
TEST(TimerTcntWrite, BlocksTheNextCompareMatchAndIsKeptWhileStoppedAtmega2560) { expect_blocking(kAtmega2560); }
TEST(TimerTcntWrite, BlocksTheNextCompareMatchAndIsKeptWhileStoppedAtmega32) { expect_blocking(kAtmega32); }

}  // namespace
}  // namespace avrbench::test::timers
