// False reds: a watchdog reset the firmware asks for is not a crash
// (periph/watchdog/WatchdogWatch.hpp); one that fires because it hung still is.
#include <gtest/gtest.h>

#include <fstream>

#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

// WDTO_15MS: 2K cycles of the 128 kHz watchdog oscillator = 16 ms = 256 000
// cycles at 16 MHz (ATmega328P §10.9.2 Table 10-3).
constexpr Cycle kFifteenMsTimeout = 16000 * 16;
// wdt_request serves its 500 ms watchdog for 20 rounds of 16 000 cycles first.
constexpr Cycle kServed = 20 * 16000;

void expect_requested(const char* firmware) {
    SCOPED_TRACE(firmware);
    Mcu mcu(ElfImage::load(test::firmware(firmware)));
    mcu.run_for(16000 * 60);  // 60 ms
    EXPECT_TRUE(mcu.findings().empty()) << mcu.findings().front().describe();
    EXPECT_EQ(mcu.resets(), 1u);
    ASSERT_EQ(mcu.requested_resets().size(), 1u);
    const auto& r = mcu.requested_resets()[0];
    EXPECT_FALSE(r.declared);
    EXPECT_GE(r.cycle, kServed + kFifteenMsTimeout);
    EXPECT_LE(r.cycle, kServed + kFifteenMsTimeout + 2000);
    EXPECT_EQ(mcu.read_ram_u8("boot_count"), 2);
    EXPECT_EQ(mcu.read_ram_u8("reset_flags") & (1 << 3), 1 << 3);  // MCUSR.WDRF (§10.9.1)
}

TEST(WatchdogRequests, EnableAndSpinIsAResetTheFirmwareAskedFor) { expect_requested("wdt_request"); }

TEST(WatchdogRequests, EnableAndSpinWithInterruptsOffAsKlipperDoesIsAskedForToo) { expect_requested("wdt_request_cli"); }

TEST(WatchdogRequests, AFirmwareThatHangsBeforeItsFirstWdrIsAFinding) {
    // wdt_hang polls a flag after enabling the watchdog: not a jump to itself.
    Mcu mcu(ElfImage::load(test::firmware("wdt_hang")));
    mcu.run_for(16000 * 40);
    ASSERT_EQ(mcu.findings().size(), 1u);
    EXPECT_EQ(mcu.findings()[0].kind, Mcu::kWatchdogReset);
    EXPECT_TRUE(mcu.requested_resets().empty());
    EXPECT_GE(mcu.findings()[0].cycle, kFifteenMsTimeout);
    EXPECT_LE(mcu.findings()[0].cycle, kFifteenMsTimeout + 2000);
}

TEST(WatchdogRequests, ABoardCanDeclareEveryResetExpected) {
    // crash_watchdog stops serving its watchdog: a finding, unless the board
    // says its firmware resets itself by design (`watchdog_resets: expected`).
    const auto dir = test::scratch_dir("verdict-wdt");
    {
        std::ofstream out(dir / "b.yaml");
        out << "board: uno-resets\nextends: arduino-uno\nmcus:\n  uno: {type: atmega328p, clock: 16MHz, watchdog_resets: expected}\n";
    }
    Bench bench((dir / "b.yaml").string(), test::firmware("crash_watchdog"));
    bench.run_for(0.04);
    EXPECT_TRUE(bench.findings().empty());
    ASSERT_EQ(bench.mcu().requested_resets().size(), 1u);
    EXPECT_TRUE(bench.mcu().requested_resets()[0].declared);
}

TEST(WatchdogRequests, TheRunSummarySaysTheResetWasAskedFor) {
    const auto dir = test::scratch_dir("verdict-wdt-cli");
    const auto r = test::run_command(std::string(test::cli()) + " run " + test::quoted(test::firmware("wdt_request")) +
                                         " --for 60ms",
                                     dir);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("reset      watchdog reset asked for by the firmware at 0.03"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("findings   0"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace avrbench
