// Seed 004's delta robot (firmware/delta on bench/boards/delta-seed004.yaml)
// against the digest's acceptance checks (../shared/seeds/digests/
// seed_004_delta.md §8): the servo frames, the pulse widths of the work
// points, the serial output of one program cycle, the magnet windows, the
// nine tack heads in the box; and the commands that make it fuzzable.
// Each test runs under ctest's 300 s wall-clock limit (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "core/FileHash.hpp"
#include "periph/usart/Uart.hpp"
#include "parts/DeltaRobot.hpp"
#include "parts/Electromagnet.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"

namespace avrbench {
namespace {

struct DeltaRun {
    Board board;
    Mcu& mega;
    test::PinLog s1, s2, s3, magnet, led;
    explicit DeltaRun(const std::string& firmware = "delta")
        : board(load_board_file(test::source_path("bench/boards/delta-seed004.yaml")), {{"mega", test::firmware(firmware)}}),
          mega(board.mcu("mega")),
          s1(mega, "PH6"),
          s2(mega, "PB4"),
          s3(mega, "PB5"),
          magnet(mega, "PB6"),
          led(mega, "PH5") {
        mega.uart(0);  // attaches the USART model now, so it hears everything from reset
    }
    static double us(Cycle cycles) { return static_cast<double>(cycles) / 16.0; }
    // The width of the last complete pulse on `log` that began before `before`.
    static double width_before(const test::PinLog& log, Cycle before) {
        const auto& e = log.edges();
        for (std::size_t i = e.size(); i-- > 1;) {
            if (!e[i].level && e[i - 1].level && e[i].cycle < before) return us(e[i].cycle - e[i - 1].cycle);
        }
        return 0;
    }
    std::string output() { return mega.uart(0).transmitted_text(); }
};

constexpr Cycle kPerSecond = 16'000'000;
// A pulse's width is exact to the 0.5 us tick; its edges move by the
// instruction the CPU is in when the compare matches (up to 4 cycles).
constexpr double kWidthUs = 0.25;

TEST(DeltaSeed004, ServoFramesAre20MsInTheOrderS1S2S3) {
    DeltaRun run;
    run.board.run_until_seconds(1.0);
    // 50 Hz: every frame exactly 20 ms (Timer1 CTC at 0.5 us per tick, 40000 ticks).
    const auto frames = test::PinLog::differences(run.s1.rises());
    ASSERT_GE(frames.size(), 45u);
    for (Cycle f : frames) EXPECT_EQ(f, 20'000u * 16u);
    // Sequential, never overlapping: S2 rises as S1 falls, S3 as S2 falls
    // (the same interrupt clears one and sets the next, a few cycles apart).
    for (std::size_t i = 0; i + 1 < run.s1.falls().size() && i < run.s2.rises().size(); ++i) {
        const Cycle gap12 = run.s2.rises()[i] - run.s1.falls()[i];
        const Cycle gap23 = run.s3.rises()[i] - run.s2.falls()[i];
        EXPECT_LT(gap12, 16u) << "frame " << i;
        EXPECT_LT(gap23, 16u) << "frame " << i;
        EXPECT_GE(run.s2.rises()[i], run.s1.falls()[i]);
        EXPECT_GE(run.s3.rises()[i], run.s2.falls()[i]);
    }
}

TEST(DeltaSeed004, BootsWithTheLedOnTheMagnetOffAndTheArmsHorizontal) {
    DeltaRun run;
    run.board.run_until_seconds(1.9);
    // Digest §8.2: D8 high within a few ms, D12 low; servoN[offset_N] = 1675 / 1583 / 1630 us.
    ASSERT_FALSE(run.led.rises().empty());
    EXPECT_LT(run.led.rises().front(), 3 * kPerSecond / 1000);
    EXPECT_TRUE(run.magnet.rises().empty());
    const Cycle now = run.mega.cycle();
    EXPECT_NEAR(DeltaRun::width_before(run.s1, now), 1675.0, kWidthUs);
    EXPECT_NEAR(DeltaRun::width_before(run.s2, now), 1583.0, kWidthUs);
    EXPECT_NEAR(DeltaRun::width_before(run.s3, now), 1630.0, kWidthUs);
}

TEST(DeltaSeed004, WorkPointsGetTheTablesPulseWidths) {
    DeltaRun run;
    // Rows start about 2 s + k s after reset (delay(2000), then 1 s dwells);
    // the pulses in the middle of row k belong to that row's point.
    struct Row {
        int index;
        double us[3];  // digest §8.4
    };
    const Row rows[] = {
        {0, {1924, 1862, 1882}},   // home (0, 0, -31)
        {1, {2040, 1531, 1769}},   // (-3.3, -6.7, -31)
        {2, {1737, 1268, 1486}},   // (-3.3, -6.7, -34)
        {5, {1765, 1396, 1981}},   // box travel (-10, 0, -31)
        {6, {1664, 1307, 1882}},   // box drop (-10, 0, -32)
        {10, {1607, 1426, 1637}},  // (-3.3, 0, -34)
        {50, {1615, 1476, 1080}},  // (10, -6.7, -34)
        {66, {1248, 1682, 1235}},  // (10, 6.7, -34)
    };
    for (const Row& r : rows) {
        const Cycle middle = static_cast<Cycle>((2.0 + r.index + 0.6) * kPerSecond);
        run.board.run_until_seconds((2.0 + r.index + 0.6));
        EXPECT_NEAR(DeltaRun::width_before(run.s1, middle), r.us[0], kWidthUs) << "row " << r.index;
        EXPECT_NEAR(DeltaRun::width_before(run.s2, middle), r.us[1], kWidthUs) << "row " << r.index;
        EXPECT_NEAR(DeltaRun::width_before(run.s3, middle), r.us[2], kWidthUs) << "row " << r.index;
    }
    // The effector reaches the point within the 1-degree rounding (digest §5:
    // up to 1.58 mm over the work points).
    const auto& robot = run.board.part_as<DeltaRobot>("robot");
    EXPECT_LT((robot.effector_mm() - Eigen::Vector3d(100, 67, -340)).norm(), 1.6);
}

TEST(DeltaSeed004, OneCycleOfTheProgramPrintsTheThesisBytesAndBinsAllNineHeads) {
    for (const char* firmware : {"delta", "delta_thesis"}) {
        DeltaRun run(firmware);
        run.board.run_until_seconds(87.0);  // one cycle: 2 + 74 rows + 10 s
        const std::string out = run.output();
        // Digest §8.5: 1082 bytes per cycle, starting with the home and first pick rows.
        ASSERT_GE(out.size(), 1082u) << firmware;
        const std::string cycle = out.substr(0, 1082);
        EXPECT_EQ(cycle.substr(0, 32), "-26\r\n-26\r\n-26\r\n\r\n-39\r\n5\r\n-14\r\n\r\n") << firmware;
        EXPECT_EQ(sha256_of_text(cycle), "ad20e808cc2a102c7064268915c355b5dcde5e567963c5ccd25ea2861394709b") << firmware;
        // The LED goes off after the 74th row (~76.2 s) and back on 10 s later.
        ASSERT_EQ(run.led.falls().size(), 1u) << firmware;
        EXPECT_NEAR(DeltaRun::us(run.led.falls()[0]) * 1e-6, 76.17, 0.3) << firmware;
        // Digest §8.6: nine magnet windows of 4 rows (4.009 s there), the first
        // from row 3 (~5 s); every one inside the LED's window (§8.8).
        ASSERT_EQ(run.magnet.rises().size(), 9u) << firmware;
        ASSERT_EQ(run.magnet.falls().size(), 9u) << firmware;
        EXPECT_NEAR(DeltaRun::us(run.magnet.rises()[0]) * 1e-6, 5.01, 0.05) << firmware;
        for (std::size_t i = 0; i < 9; ++i) {
            const double window_s = DeltaRun::us(run.magnet.falls()[i] - run.magnet.rises()[i]) * 1e-6;
            EXPECT_NEAR(window_s, 4.009, 0.02) << firmware << " window " << i;
            EXPECT_LT(run.magnet.falls()[i], run.led.falls()[0]) << firmware;
        }
        // All nine tack heads picked and dropped into the box; none left on the magnet.
        const auto& magnet = run.board.part_as<Electromagnet>("magnet");
        EXPECT_EQ(magnet.in_box(), 9u) << firmware;
        EXPECT_EQ(magnet.carried(), 0u) << firmware;
        EXPECT_TRUE(run.board.findings().empty()) << firmware;
    }
}

TEST(DeltaSeed004, CommandsMoveToReachablePointsAndRejectTheRest) {
    DeltaRun run;
    run.board.run_until_seconds(0.5);
    Uart& uart = run.mega.uart(0);
    uart.send("G1 X100 Y-67 Z-340\n");
    run.board.run_until_seconds(2.0);
    uart.send("G1 Z-500\n");  // below r_f + r_e: no arm reaches it
    run.board.run_until_seconds(2.5);
    uart.send("G1 X0 Y151 Z-360\n");  // the arms reach it, but arm 1 at 111.8 deg needs table index -1
    run.board.run_until_seconds(3.0);
    uart.send("M3\nG2\n");
    run.board.run_until_seconds(3.5);
    EXPECT_EQ(run.output().substr(run.output().find("ok\r\n")),
              "ok\r\nerror: unreachable\r\nerror: unreachable\r\nok\r\nerror: unknown command\r\n");
    // The servos hold the first target's pulses (digest §8.4: 1615 / 1476 / 1080 us).
    const Cycle now = run.mega.cycle();
    EXPECT_NEAR(DeltaRun::width_before(run.s1, now), 1615.0, kWidthUs);
    EXPECT_NEAR(DeltaRun::width_before(run.s3, now), 1080.0, kWidthUs);
    EXPECT_FALSE(run.magnet.rises().empty());  // M3
    EXPECT_TRUE(run.board.findings().empty());
}

TEST(DeltaSeed004, TheListingsBuildUsesUnreachableAnglesAnyway) {
    DeltaRun run("delta_thesis");
    run.board.run_until_seconds(0.5);
    run.mega.uart(0).send("G1 X0 Y151 Z-360\n");
    run.board.run_until_seconds(1.0);
    // No checks: "ok", and the table index offset - angle leaves 0..180.
    EXPECT_NE(run.output().find("ok\r\n"), std::string::npos);
    EXPECT_EQ(run.output().find("error"), std::string::npos);
}

}  // namespace
}  // namespace avrbench
