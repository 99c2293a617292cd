// A board's serial port on a pseudo-terminal (stimulus/PtyBridge): what a
// host writes to the pty reaches the firmware, and what the firmware sends
// comes out of it. The host here is this test, on the pty's slave side, as
// a terminal or avrdude would be.
#include <gtest/gtest.h>
#include <sim_avr.h>

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "periph/usart/Uart.hpp"
#include "stimulus/PtyBridge.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

TEST(Pty, BytesGoBothWaysThroughThePseudoTerminal) {
    const auto dir = test::scratch_dir("pty");
    const std::string link = (dir / "ttyUNO").string();
    Bench bench(test::source_path("bench/boards/arduino-uno.yaml"), test::firmware("uart_echo"));
    std::string received;
    {
        PtyBridge pty(bench.serial("host"), link);
        EXPECT_EQ(std::filesystem::read_symlink(link).string(), pty.path());
        const int host = ::open(link.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
        ASSERT_GE(host, 0) << pty.path();
        ASSERT_EQ(::write(host, "hello pty\n", 10), 10);
        // uart_echo: a banner, then every byte back; 115200 baud (117647 with
        // U2X), 85 us per frame: 30 bytes in well under 10 ms.
        for (int slice = 0; slice < 100 && received.find("hello pty\n") == std::string::npos; ++slice) {
            bench.board().run_for_seconds(0.001);
            pty.pump();
            char buf[256];
            const ssize_t n = ::read(host, buf, sizeof buf);
            if (n > 0) received.append(buf, static_cast<std::size_t>(n));
        }
        EXPECT_EQ(pty.bytes_to_firmware(), 10u);
        EXPECT_EQ(pty.bytes_to_host(), 30u);  // 20 banner bytes + 10 echoed
        ::close(host);
    }
    EXPECT_EQ(received, "avrbench uart_echo\r\nhello pty\n");
    EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(link)));  // removed with the bridge
    // The firmware's side of it, as the bench records it.
    EXPECT_EQ(bench.serial("host").transmitted_text(), "avrbench uart_echo\r\nhello pty\n");
}

TEST(Pty, TheCliPrintsThePathAtOnceAndCountsTheBytes) {
    const auto dir = test::scratch_dir("pty-cli");
    const std::string cli = std::string(::avrbench::test::cli()) + " run " + test::firmware("uart_echo") + " --board " +
                            test::source_path("bench/boards/arduino-uno.yaml");
    const auto r = test::run_command(cli + " --pty host --for 10ms", dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out.rfind("avrbench run: serial host on /dev/pts/", 0), 0u) << r.out;
    EXPECT_NE(r.out.find("  pty        /dev/pts/"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("0 bytes to the firmware, 20 from it"), std::string::npos) << r.out;
    const auto bad = test::run_command(cli + " --pty host --pace slow --for 10ms", dir);
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_EQ(bad.err, "avrbench: error: --pace: 'slow' is not free or realtime\n");
    const auto lone = test::run_command(cli + " --reset-on-open --for 10ms", dir);
    EXPECT_EQ(lone.exit_code, 2);
    EXPECT_EQ(lone.err, "avrbench: error: --reset-on-open: needs --pty PORT (the port whose opening resets its MCU)\n");
    const auto counted = test::run_command(cli + " --pty host --reset-on-open --for 10ms", dir);
    EXPECT_NE(counted.out.find("20 from it, 0 resets on open"), std::string::npos) << counted.out;
}

// An Arduino resets when the host opens its port (DTR through a capacitor to
// RESET); avrdude's -c arduino relies on it to reach the bootloader. A pty
// has no DTR, so the bridge reports each open (inotify IN_OPEN) and the run
// pulses RESET: the firmware starts over, MCUSR.EXTRF set (328P §10.2, §10.9.1).
TEST(Pty, OpeningThePortCanResetTheMcuAsAnArduinoDoes) {
    Bench bench(test::source_path("bench/boards/arduino-uno.yaml"), test::firmware("uart_echo"));
    Mcu& uno = bench.mcu();
    PtyBridge pty(bench.serial("host"));
    bench.board().run_for_seconds(0.005);
    EXPECT_FALSE(pty.host_opened());  // the bridge's own open does not count
    const int host = ::open(pty.path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(host, 0);
    EXPECT_TRUE(pty.host_opened());
    EXPECT_FALSE(pty.host_opened());  // once per open
    uno.reset_external();
    EXPECT_EQ(uno.pc_bytes(), 0u);
    // MCUSR (0x54 in data space on the 328P): EXTRF is bit 1.
    EXPECT_EQ(uno.peek(0x54) & 0x02, 0x02);
    bench.board().run_for_seconds(0.005);
    EXPECT_EQ(bench.serial("host").transmitted_text(), "avrbench uart_echo\r\navrbench uart_echo\r\n");
    EXPECT_EQ(uno.resets(), 1u);
    EXPECT_TRUE(uno.findings().empty());  // a reset pulse is not a fault of the firmware
    ::close(host);
    const int again = ::open(pty.path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    EXPECT_TRUE(pty.host_opened());
    ::close(again);
}

}  // namespace
}  // namespace avrbench
