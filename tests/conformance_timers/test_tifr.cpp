// Clearing and enabling timer interrupt flags (firmware/conformance/timers/
// tmr_tifr, tmr_flag_enable).
//
// ATmega328P datasheet §16.11.9 (TIFR1): a flag "can be cleared by writing a
// logic one to its bit location"; §8.5 "I/O Memory": "unlike most
// other AVRs, the CBI and SBI instructions will only operate on the specified
// bit, and can therefore be used on registers containing such Status Flags"
// (ATmega2560: the same note). The ATmega32's TIFR is at I/O 0x38, out of
// SBI/CBI's reach: `TIFR |= x` is IN, ORI, OUT there and writes a one to every
// flag that reads set.
// §7.7: "If an interrupt condition occurs while the corresponding interrupt
// enable bit is cleared, the Interrupt Flag will be set and remembered until
// the interrupt is enabled, or the flag is cleared by software."
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

std::vector<unsigned> tifr_steps(const TimerPart& part) {
    Mcu mcu(timer_firmware("tmr_tifr", part));
    mcu.run_for(5000);
    EXPECT_EQ(mcu.read_ram_u8("done"), 1);
    return ram_bytes(mcu, "r", 7);
}

// TIFR1 bits: OCF1B 2, OCF1A 1, TOV1 0 (all set: 0x07). The steps (tmr_tifr/main.c):
// [0] all set; [1] OUT 1<<OCF1A clears OCF1A only; [2] SBI TOV1 clears TOV1
// only; [3] CBI OCF1B writes nothing; [4] writing 0 clears nothing; [5] all
// set again; [6] writing back what was read clears all of them.
TEST(TimerTifr, WriteOneClearsOnlyThatFlagByOutAndBySbiAtmega328p) {
    EXPECT_EQ(tifr_steps(kAtmega328p), (std::vector<unsigned>{0x07, 0x05, 0x04, 0x04, 0x04, 0x07, 0x00}));
}

// The 2560's Timer1 has a third comparator: OCR1C = 0 (its reset value) matches
// when TCNT1 wraps from 0xFFFF through 0, so OCF1C (bit 3) is set with the
// others (§17.11.36) and, never written, stays set until [6].
TEST(TimerTifr, WriteOneClearsOnlyThatFlagByOutAndBySbiAtmega2560) {
    EXPECT_EQ(tifr_steps(kAtmega2560), (std::vector<unsigned>{0x0F, 0x0D, 0x0C, 0x0C, 0x0C, 0x0F, 0x00}));
}

// ATmega32 TIFR bits: OCF1A 4, OCF1B 3, TOV1 2 (all set: 0x1C). [2] is a
// read-modify-write (IN/ORI/OUT) that writes ones to OCF1B and TOV1: both go.
TEST(TimerTifr, WriteOneClearsOnlyTheFlagsWrittenAtmega32) {
    EXPECT_EQ(tifr_steps(kAtmega32), (std::vector<unsigned>{0x1C, 0x0C, 0x00, 0x00, 0x00, 0x1C, 0x00}));
}

// OCF1A set while OCIE1A = 0 (and I = 1); marker 0 toggles on the instruction
// before the write of OCIE1A, marker 1 first thing in the vector. The vector
// must follow the write at once: the write (STS, 2 cycles), the interrupt
// response (§7.7.1: 4 cycles, 5 on the 2560), the vector's JMP (3 cycles) and
// the ISR prologue up to the marker (under 30 cycles in every build, see the
// .lst), not at the next match 60001 cycles later.
void expect_enable_fires(const TimerPart& part, const char* marker0, const char* marker1) {
    Mcu mcu(timer_firmware("tmr_flag_enable", part));
    PinLog m0(mcu, marker0);
    PinLog m1(mcu, marker1);
    mcu.run_for(70000);
    ASSERT_EQ(m0.edges().size(), 1u);
    ASSERT_GE(m1.edges().size(), 1u) << "the vector never ran";
    EXPECT_LT(m1.edges()[0].cycle - m0.edges()[0].cycle, 60u);
    EXPECT_EQ(mcu.read_ram_u8("isr_count"), 1);
}

TEST(TimerFlagBeforeEnable, VectorRunsAsSoonAsEnabledAtmega328p) { expect_enable_fires(kAtmega328p, "PC0", "PC1"); }
TEST(TimerFlagBeforeEnable, VectorRunsAsSoonAsEnabledAtmega2560) { expect_enable_fires(kAtmega2560, "PF0", "PF1"); }
TEST(TimerFlagBeforeEnable, VectorRunsAsSoonAsEnabledAtmega32) { expect_enable_fires(kAtmega32, "PC0", "PC1"); }

}  // namespace
}  // namespace avrbench::test::timers
