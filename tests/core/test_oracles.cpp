// Crash oracles: each fault firmware must be caught with its kind, the cycle,
// the PC and the nearest symbol.
#include <gtest/gtest.h>

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

const Finding& only_finding(const Mcu& mcu) {
    EXPECT_EQ(mcu.findings().size(), 1u);
    static const Finding none{};
    return mcu.findings().empty() ? none : mcu.findings().front();
}

TEST(Oracles, InvalidOpcodeIsReportedAtItsAddress) {
    Mcu mcu(ElfImage::load(test::firmware("crash_bad_opcode")));
    EXPECT_EQ(mcu.run_for(16000000), StopReason::Halted);
    const Finding& f = only_finding(mcu);
    EXPECT_EQ(f.kind, Mcu::kInvalidOpcode);
    EXPECT_EQ(f.pc_bytes, *mcu.elf().symbol_address("bad_opcode_here"));
    EXPECT_EQ(f.symbol, "bad_opcode_here");
    EXPECT_GT(f.cycle, 0u);
    EXPECT_LT(f.cycle, 16000u);  // right after start-up, not at the time limit
}

TEST(Oracles, StackIntoBssIsReported) {
    Mcu mcu(ElfImage::load(test::firmware("crash_stack_overflow")));
    EXPECT_EQ(mcu.run_for(16000000), StopReason::Halted);
    const Finding& f = only_finding(mcu);
    EXPECT_EQ(f.kind, Mcu::kStackOverflow);
    EXPECT_NE(f.detail.find("below the end of .data/.bss"), std::string::npos) << f.detail;
    // Caught at the first instruction that moved SP below __bss_end - 1: a
    // push, a call, or recurse()'s prologue allocating its 16-byte volatile
    // frame plus saved registers in one SP write, so SP is at most one frame
    // (16 + a few saved registers, < 32 bytes) below the floor.
    const unsigned sp = mcu.stack_pointer();
    const unsigned bss_end = mcu.elf().ram_end_of_static_data();
    EXPECT_LT(sp, bss_end - 1);
    EXPECT_GT(sp + 32, bss_end - 1);
    EXPECT_EQ(f.symbol.rfind("recurse", 0), 0u) << f.symbol;
}

TEST(Oracles, UnhandledInterruptReachesBadInterrupt) {
    Mcu mcu(ElfImage::load(test::firmware("crash_bad_interrupt")));
    EXPECT_EQ(mcu.run_for(16000000), StopReason::Halted);
    const Finding& f = only_finding(mcu);
    EXPECT_EQ(f.kind, Mcu::kBadInterrupt);
    EXPECT_EQ(f.symbol, "__bad_interrupt");
    // TIMER0_OVF is vector 17 in the datasheet's 1-based table (ATmega328P
    // §12.4 table 12-6), program address 0x0020 words = 0x0040 bytes.
    EXPECT_NE(f.detail.find("0x0040"), std::string::npos) << f.detail;
    // Timer0 at prescaler 1 overflows after 256 cycles: the finding comes
    // within the first few hundred cycles after sei.
    EXPECT_LT(f.cycle, 2000u);
}

TEST(Oracles, WatchdogResetIsReportedAndTheFirmwareSeesWdrf) {
    Mcu mcu(ElfImage::load(test::firmware("crash_watchdog")));
    mcu.run_for(16000 * 40);  // 40 ms
    ASSERT_EQ(mcu.findings().size(), 1u);
    const Finding& f = mcu.findings().front();
    EXPECT_EQ(f.kind, Mcu::kWatchdogReset);
    // WDTO_15MS: WDP = 0, 2K cycles of the 128 kHz watchdog oscillator = 16 ms
    // (ATmega328P §10.9.2 table 10-3). The reset comes 16 ms after the
    // firmware's last WDR: five rounds of 16000 cycles after the watchdog was
    // enabled, which happens within the first few hundred cycles.
    const Cycle sixteen_ms = 16000 * 16, served = 5 * 16000;
    EXPECT_GE(f.cycle, served + sixteen_ms);
    EXPECT_LE(f.cycle, served + sixteen_ms + 2000);
    EXPECT_TRUE(mcu.requested_resets().empty());
    EXPECT_EQ(mcu.resets(), 1u);
    EXPECT_FALSE(mcu.halted());  // a watchdog reset restarts the firmware, as on silicon
    // MCUSR.WDRF is bit 3 (§10.9.1); the firmware copies MCUSR to reset_flags.
    EXPECT_EQ(mcu.read_ram_u8("reset_flags") & (1 << 3), 1 << 3);
}

TEST(Oracles, JumpPastTheProgramIsReported) {
    Mcu mcu(ElfImage::load(test::firmware("crash_pc_outside_flash")));
    EXPECT_EQ(mcu.run_for(16000000), StopReason::Halted);
    const Finding& f = only_finding(mcu);
    EXPECT_EQ(f.kind, Mcu::kPcOutsideProgram);
    EXPECT_EQ(f.pc_bytes, 0x3000u * 2);  // the firmware calls word address 0x3000
    EXPECT_NE(f.describe().find("cycle"), std::string::npos);
}

TEST(Oracles, HealthyFirmwareHasNoFindings) {
    Mcu mcu(ElfImage::load(test::firmware("blink_timer1")));
    EXPECT_EQ(mcu.run_for(16000000 / 10), StopReason::ReachedTarget);
    EXPECT_TRUE(mcu.findings().empty());
    EXPECT_FALSE(mcu.halted());
}

}  // namespace
}  // namespace avrbench
