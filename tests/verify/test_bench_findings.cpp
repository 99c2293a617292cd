// Host findings carry the clock of their port's MCU, so their time reads in
// seconds like every other finding.
#include <gtest/gtest.h>

#include "support/Paths.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

TEST(BenchFindings, AHostTimeoutSaysItsTimeInSecondsAndCycles) {
    // busy_poll never reads its UART: the line sent at power-on gets no
    // answer, and the host gives up after its 2 s line timeout
    // (UartHostOptions::line_timeout_s) = 32,000,000 cycles at 16 MHz.
    Bench bench(test::source_path("bench/boards/arduino-uno.yaml"), test::firmware("busy_poll"));
    bench.host().add_line("G1 X1");
    ASSERT_EQ(bench.run_until_idle(3.0), IdleResult::HostFailed);
    const auto findings = bench.findings();
    ASSERT_EQ(findings.size(), 1u);
    EXPECT_EQ(findings[0].clock_hz, 16000000u);
    const std::string text = findings[0].describe();
    EXPECT_NE(text.find("host: host-protocol at 2.0000"), std::string::npos) << text;
    EXPECT_NE(text.find(" s (cycle 3200"), std::string::npos) << text;
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(BenchIdle, QuietIsCountedFromTheLastHostLineNotFromPowerOn) {
    // grbl answers "ok" when a move is planned and steps after it; no STEP
    // edge yet must not make the board idle the moment the ok arrives.
    // host_peer_grbl answers at once and never steps: idle comes exactly one
    // settle time (300 ms) after its last line.
    Bench bench(test::source_path("bench/boards/arduino-uno.yaml"), test::firmware("host_peer_grbl"));
    UartHostOptions o = default_host_options(bench.serial_port());
    o.family = FirmwareFamily::Grbl;
    bench.host("", o).add_line("G1 X1");
    ASSERT_EQ(bench.run_until_idle(5.0, 0.3), IdleResult::Idle);
    const auto& transcript = bench.host().transcript();
    ASSERT_FALSE(transcript.empty());
    const double last_line_s = static_cast<double>(transcript.back().cycle) / 16e6;
    EXPECT_GE(bench.now_seconds(), last_line_s + 0.3);
    EXPECT_LT(bench.now_seconds(), last_line_s + 0.3 + 0.08);  // within one 75 ms slice
}

}  // namespace
}  // namespace avrbench
