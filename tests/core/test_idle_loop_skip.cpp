// mcu/IdleLoopSkip on loops whose numbers can be worked out by hand. The
// every-firmware exactness check is RunLoop.SkippingIdleLoopsEndsWhereAvrRunEndsOnEveryFirmware.
#include <gtest/gtest.h>

#include <vector>

extern "C" {
#include <sim_avr.h>
}

#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

struct End {
    Cycle cycle;
    std::uint32_t pc;
    std::vector<std::uint8_t> data;
};

End run_to(Mcu& mcu, Cycle cycle) {
    mcu.run_until(cycle);
    return {mcu.cycle(), mcu.pc_bytes(), mcu.data_memory()};
}

// twi_master starts with _delay_us(50): avr-gcc's __builtin_avr_delay_cycles
// makes it `ldi r24,0xC7; ldi r25,0; sbiw r24,1; brne .-4` (twi_master.lst),
// 199 passes of 4 cycles, the last one falling through in 3. Where in the
// loop the skipper first looks depends on its back-off after the start-up
// code; from there it adds the passes that still come back, less the one it
// leaves to run for real, in one jump: at most 197 passes (788 cycles), a
// whole number of 4-cycle passes, each two instructions not stepped.
TEST(IdleLoopSkip, CountDownDelayLoopIsAddedUpInOneJump) {
    McuOptions skipping;
    McuOptions plain;
    plain.skip_idle_loops = false;
    Mcu a(ElfImage::load(test::firmware("twi_master")), skipping);
    Mcu b(ElfImage::load(test::firmware("twi_master")), plain);
    // 50 us = 800 cycles of delay after a few dozen of start-up: 840 is
    // just past it, before the firmware touches the TWI.
    const End ea = run_to(a, 840), eb = run_to(b, 840);
    EXPECT_EQ(ea.cycle, eb.cycle);
    EXPECT_EQ(ea.pc, eb.pc);
    EXPECT_TRUE(ea.data == eb.data);
    EXPECT_EQ(a.idle_jumps(), 1u);
    EXPECT_GT(a.idle_cycles_skipped(), 0u);
    EXPECT_LE(a.idle_cycles_skipped(), 788u);
    EXPECT_EQ(a.idle_cycles_skipped() % 4, 0u);
    EXPECT_EQ(b.idle_jumps(), 0u);
    // Two instructions per skipped pass were not stepped.
    EXPECT_EQ(b.steps() - a.steps(), a.idle_cycles_skipped() / 2);
}

// uart_echo waits for a byte in a polling loop on UCSR0A: a fixed point that
// lasts until the run's end, jumped over whole, landing exactly where the
// plain run stops.
TEST(IdleLoopSkip, PollingLoopIsJumpedToTheEndOfTheRun) {
    McuOptions plain;
    plain.skip_idle_loops = false;
    Mcu a(ElfImage::load(test::firmware("uart_echo")));
    Mcu b(ElfImage::load(test::firmware("uart_echo")), plain);
    const Cycle end = a.cycles_from_seconds(0.5);
    const End ea = run_to(a, end), eb = run_to(b, end);
    EXPECT_EQ(ea.cycle, eb.cycle);
    EXPECT_EQ(ea.pc, eb.pc);
    EXPECT_TRUE(ea.data == eb.data);
    EXPECT_GT(a.idle_jumps(), 0u);
    // Nearly all of the half second: only the start-up and one watched pass ran.
    EXPECT_GT(a.idle_cycles_skipped(), end - 20'000);
    EXPECT_LT(a.steps(), 20'000u);
}

}  // namespace
}  // namespace avrbench
