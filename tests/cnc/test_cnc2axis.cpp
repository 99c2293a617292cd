// Seed 002's pen plotter firmware (firmware/cnc2axis) on its board
// (bench/boards/cnc2axis-seed002.yaml), driven by binary records as the
// thesis' PC program sends them. Expected values: the digest's acceptance
// checks (../shared/seeds/digests/seed_002_cnc.md §7), each computed beside it.
// Each test runs under ctest's 300 s wall-clock limit (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "periph/usart/Uart.hpp"
#include "parts/Axis.hpp"
#include "parts/PenLift.hpp"
#include "parts/StepDirDriver.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"

namespace avrbench {
namespace {

constexpr std::uint8_t kAck = 0x06, kNak = 0x15;
// START byte bits: PB0 X DIR, PB2 X EN (1 = off), PB4 Y EN, PB5 Y DIR.
constexpr std::uint8_t kXNeg = 0x01, kXOff = 0x04, kYOff = 0x10, kYNeg = 0x20;

struct CncRun {
    Board board;
    Mcu& uno;
    StepDirDriver& xd;
    StepDirDriver& yd;
    Axis& x;
    Axis& y;
    test::PinLog x_step, servo;
    bool improved;

    explicit CncRun(const std::string& firmware = "cnc2axis")
        : board(load_board_file(test::source_path("bench/boards/cnc2axis-seed002.yaml")), {{"uno", test::firmware(firmware)}}),
          uno(board.mcu("uno")),
          xd(board.part_as<StepDirDriver>("x_driver")),
          yd(board.part_as<StepDirDriver>("y_driver")),
          x(board.part_as<Axis>("x")),
          y(board.part_as<Axis>("y")),
          x_step(uno, "PD6"),
          servo(uno, "PB1"),
          improved(firmware == "cnc2axis_improved") {
        uno.uart(0);  // listen from reset
        double t = 0;
        while (uno.read_ram_u8("homed") == 0 && t < 5) board.run_until_seconds(t += 0.1);
        EXPECT_EQ(uno.read_ram_u8("homed"), 1) << "homing did not finish";
    }
    void count(std::vector<std::uint8_t>& out, std::uint32_t v) const {
        for (int i = 0; i < (improved ? 3 : 2); ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    }
    std::vector<std::uint8_t> g00(std::uint32_t sx, std::uint32_t sy, std::uint8_t ocr0, std::uint8_t ocr2, std::uint8_t start) const {
        std::vector<std::uint8_t> r{0x00};
        count(r, sx);
        count(r, sy);
        r.insert(r.end(), {ocr0, ocr2, start});
        return r;
    }
    std::vector<std::uint8_t> g01(std::uint32_t sx, std::uint32_t sy, std::uint8_t ocr0, std::uint8_t ocr2, std::uint8_t start) const {
        std::vector<std::uint8_t> r{0x01};
        count(r, sx);
        if (improved) count(r, sy);
        r.insert(r.end(), {ocr0, ocr2, start});
        return r;
    }
    void send(const std::vector<std::uint8_t>& bytes) { uno.uart(0).send(std::string(bytes.begin(), bytes.end())); }
    std::string received() { return uno.uart(0).transmitted_text(); }
    // Runs until the firmware has sent `n` ACKs in all (or the limit).
    void run_until_acks(unsigned n, double limit_s) {
        double t = board.now_seconds();
        while (uno.read_ram_u16("acks") < n && t < limit_s && !uno.halted()) board.run_until_seconds(t += 0.05);
        ASSERT_GE(uno.read_ram_u16("acks"), n) << "no ACK by " << limit_s << " s";
    }
};

TEST(Cnc2Axis, HomesBothAxesBeforeTheFirstRecord) {
    CncRun run;
    // The carriages start at 40 and 25 mm: 40 * 160 and 25 * 160 microsteps home.
    EXPECT_EQ(run.x.position_mm(), 0.0);
    EXPECT_EQ(run.y.position_mm(), 0.0);
    EXPECT_EQ(run.xd.steps_taken(), 6400u);
    EXPECT_EQ(run.yd.steps_taken(), 4000u);
    EXPECT_TRUE(run.uno.pin("PD2").level());  // the switches read 1 at the origin
    EXPECT_TRUE(run.uno.pin("PD3").level());
    EXPECT_TRUE(run.uno.pin("PB2").level());  // both drivers off
    EXPECT_TRUE(run.uno.pin("PB4").level());
    EXPECT_TRUE(run.board.findings().empty());  // no crash into the frame, DRV8825 timing kept
}

// Homing in the thesis' order (digest §1: re-read after the debounce, then
// switch the driver off): the motor steps on through the 2 ms delay. At the
// homing rate, one step per 2 * 1024 * (3 + 1) = 8192 cycles, 2 ms = 32 000
// cycles hold 3 or 4 steps (by phase) past the switch at 0 mm - what digest
// §7 check 3 bounds ("at most the steps issued during the debounce delay") -
// and the run reports the carriage driven past its end of travel.
TEST(Cnc2Axis, HomingInTheThesisOrderOvershootsTheOriginByTheDebounceSteps) {
    CncRun run("cnc2axis_homing_as_written");
    const auto x_over = run.xd.steps_taken() - 6400u, y_over = run.yd.steps_taken() - 4000u;
    EXPECT_GE(x_over, 3u);
    EXPECT_LE(x_over, 4u);
    EXPECT_GE(y_over, 3u);
    EXPECT_LE(y_over, 4u);
    std::size_t out_of_travel = 0;
    for (const Finding& f : run.board.findings()) out_of_travel += f.kind == Axis::kAxisOutOfTravel ? 1 : 0;
    EXPECT_EQ(out_of_travel, 2u);  // x and y
}

TEST(Cnc2Axis, StepPeriodIsTwoNTimesOcrPlusOne) {
    CncRun run;
    // G01 (0,0) -> (10,0) at OCR0A = 3: 10 mm * 160 = 1600 X steps, Y off.
    run.send(run.g01(1600, 0, 3, 3, kYOff));
    run.run_until_acks(1, 5);
    EXPECT_EQ(run.xd.steps_taken(), 6400u + 1600u);
    EXPECT_EQ(run.yd.steps_taken(), 4000u);  // Y's pulses ran, ignored while disabled
    EXPECT_NEAR(run.x.position_mm(), 10.0, 1e-9);
    // 2 * N * (OCR0A + 1) = 2 * 1024 * 4 = 8192 cycles per step (512 us,
    // 1953.125 Hz, 12.207 mm/s), high half of it.
    const auto periods = test::PinLog::differences(run.x_step.rises());
    ASSERT_GE(periods.size(), 1600u);
    for (std::size_t i = periods.size() - 1500; i < periods.size(); ++i) EXPECT_EQ(periods[i], 8192u);
    const auto highs = run.x_step.high_times();
    EXPECT_EQ(highs.back(), 4096u);
    EXPECT_EQ(std::string(1, static_cast<char>(kAck)), run.received());
}

TEST(Cnc2Axis, DiagonalG01CountsXAndRunsYOpenLoop) {
    for (const char* firmware : {"cnc2axis", "cnc2axis_improved"}) {
        CncRun run(firmware);
        // (0,0) -> (10,5): OCR0A = 4 (1562.5 steps/s on X), OCR2A = 9 (781.25 on Y):
        // X 1600 steps take 1.024 s, in which Y makes 781.25 * 1.024 = 800 (+-1) steps.
        run.send(run.g01(1600, 800, 4, 9, 0));
        run.run_until_acks(1, 5);
        EXPECT_EQ(run.xd.steps_taken() - 6400u, 1600u) << firmware;
        const auto y_steps = static_cast<double>(run.yd.steps_taken() - 4000u);
        if (run.improved) {
            EXPECT_EQ(y_steps, 800.0) << firmware;  // counted
        } else {
            EXPECT_NEAR(y_steps, 800.0, 1.0) << firmware;  // open loop
        }
        EXPECT_NEAR(run.y.position_mm(), 5.0, 1.0 / 160.0 + 1e-9) << firmware;
        EXPECT_TRUE(run.board.findings().empty()) << firmware;
    }
}

// Appendix A3's G_01 sets TCCR2B = 0b110: Timer2 at clk/256 (digest §4:
// "comment says 128; bits = clk/256"), while the PC computes OCR2A for 1024
// (check 7). The same record then runs Y at 16e6 / (2 * 256 * 10) = 3125
// steps/s for X's 1.024 s: 3200 (+-1) steps, 20 mm instead of 5.
TEST(Cnc2Axis, G01WithTheListingsTimer2PrescalerRunsYFourTimesTooFar) {
    CncRun run("cnc2axis_g01_timer2_as_written");
    run.send(run.g01(1600, 800, 4, 9, 0));
    run.run_until_acks(1, 5);
    EXPECT_EQ(run.xd.steps_taken() - 6400u, 1600u);
    EXPECT_NEAR(static_cast<double>(run.yd.steps_taken() - 4000u), 3200.0, 1.0);
    EXPECT_NEAR(run.y.position_mm(), 20.0, 1.0 / 160.0 + 1e-9);
}

TEST(Cnc2Axis, LongMovesWrapIn16BitsAndAreExactIn24) {
    // 460 mm at 1/32 = 73600 microsteps; 16 bits hold 73600 - 65536 = 8064
    // (50.4 mm, digest §5 Table 6.2 and §7.12). G00 at OCR0A = 0 (48.8 mm/s).
    {
        CncRun run("cnc2axis");
        run.send(run.g00(73600, 0, 0, 0, kYOff));
        run.run_until_acks(1, 20);
        EXPECT_NEAR(run.x.position_mm(), 50.4, 1e-9);
    }
    {
        CncRun run("cnc2axis_improved");
        run.send(run.g00(73600, 0, 0, 0, kYOff));
        run.run_until_acks(1, 20);
        EXPECT_NEAR(run.x.position_mm(), 460.0, 1e-9);
        EXPECT_TRUE(run.board.findings().empty());
    }
}

TEST(Cnc2Axis, G00CountsBothAxesAndTheShorterStopsFirst) {
    CncRun run;
    // (0,0) -> (5,10) at v_max: 800 X and 1600 Y microsteps.
    run.send(run.g00(800, 1600, 0, 0, 0));
    run.run_until_acks(1, 5);
    EXPECT_NEAR(run.x.position_mm(), 5.0, 1e-9);
    EXPECT_NEAR(run.y.position_mm(), 10.0, 1e-9);
    // Back to the origin: DIR = 1 on both.
    run.send(run.g00(800, 1600, 0, 0, kXNeg | kYNeg));
    run.run_until_acks(2, 5);
    EXPECT_NEAR(run.x.position_mm(), 0.0, 1e-9);
    EXPECT_NEAR(run.y.position_mm(), 0.0, 1e-9);
}

TEST(Cnc2Axis, ArcRecordsArePipelinedWithOneAckEach) {
    CncRun run;
    run.send(run.g00(1600, 1600, 0, 0, 0));  // to (10, 10)
    run.run_until_acks(1, 5);
    // A G03 as chords: each record moves DX X microsteps at V_X while Y runs at V_Y.
    std::vector<std::uint8_t> arc{0x03};
    const std::uint8_t chords[][4] = {{200, 4, 9, 0}, {150, 4, 6, 0}, {100, 4, 4, kXNeg}, {0, 4, 4, kXOff | kYOff}};
    for (const auto& c : chords) arc.insert(arc.end(), c, c + 4);
    const auto before = run.xd.steps_taken();
    run.send(arc);
    run.run_until_acks(1 + 4, 10);
    run.board.run_for_seconds(0.5);
    EXPECT_EQ(run.received(), std::string(5, static_cast<char>(kAck)));
    // X counted per chord: 200 + 150 + 100 (the motors turn on between
    // chords until the next loads, as the thesis notes: at most a step more each).
    const auto x_steps = run.xd.steps_taken() - before;
    EXPECT_GE(x_steps, 450u);
    EXPECT_LE(x_steps, 453u);
    EXPECT_TRUE(run.board.part_as<PenLift>("pen").down());  // drawing
}

TEST(Cnc2Axis, M30DisablesSleepsAndLiftsThePen) {
    for (const std::string firmware : {"cnc2axis", "cnc2axis_improved"}) {
        SCOPED_TRACE(firmware);
        CncRun run(firmware);
        // A G01 first: the pen goes down (OCR1A = 2000), so lifting it is something M30 does.
        run.send(run.g01(160, 0, 3, 3, kYOff));
        run.run_until_acks(1, 5);
        run.board.run_for_seconds(0.3);
        EXPECT_TRUE(run.board.part_as<PenLift>("pen").down());
        run.send({0x7F, 0x3B});  // an unknown command byte, then M30
        run.board.run_for_seconds(0.5);
        const std::string ack_nak_ack{static_cast<char>(kAck), static_cast<char>(kNak), static_cast<char>(kAck)};
        EXPECT_EQ(run.received(), ack_nak_ack);
        EXPECT_TRUE(run.uno.halted());
        EXPECT_NE(run.uno.halt_reason().find("SLEEP with interrupts disabled"), std::string::npos);
        EXPECT_TRUE(run.uno.pin("PB2").level());
        EXPECT_TRUE(run.uno.pin("PB4").level());
        EXPECT_FALSE(run.board.part_as<PenLift>("pen").down());
    }
}

TEST(Cnc2Axis, PenServoIsPhaseCorrectPwmMode10) {
    CncRun run;
    run.board.run_for_seconds(0.2);
    // Mode 10, ICR1 = 19999, clk/8: period 2 * 8 * 19999 = 319984 cycles
    // (50.0025 Hz); OCR1A = 1499: high 2 * 8 * 1499 = 23984 cycles (1.499 ms).
    const auto periods = test::PinLog::differences(run.servo.rises());
    ASSERT_GE(periods.size(), 5u);
    EXPECT_EQ(periods.back(), 319984u);
    EXPECT_EQ(run.servo.high_times().back(), 23984u);
    // G01 puts the pen down: OCR1A = 2000 -> 32000 cycles (2.0 ms, +90 deg).
    run.send(run.g01(160, 0, 3, 3, kYOff));
    run.run_until_acks(1, 5);
    run.board.run_for_seconds(0.1);
    EXPECT_EQ(run.servo.high_times().back(), 32000u);
}

// The servo as the thesis names its mode, "Fast PWM mode 14", with the same
// ICR1 = 19999 and OCR1A (digest §1, §7 check 13): period 8 * (19999 + 1)
// = 160 000 cycles (100 Hz), pen up 8 * (1499 + 1) = 12 000 cycles
// (0.75 ms), pen down 8 * (2000 + 1) = 16 008 cycles (1.0 ms): half the
// widths the thesis' formula promises, at twice the rate.
TEST(Cnc2Axis, PenServoInTheThesisNamedMode14RunsAtTwiceTheRateWithHalfThePulse) {
    CncRun run("cnc2axis_servo_mode14");
    run.board.run_for_seconds(0.2);
    const auto periods = test::PinLog::differences(run.servo.rises());
    ASSERT_GE(periods.size(), 5u);
    EXPECT_EQ(periods.back(), 160000u);
    EXPECT_EQ(run.servo.high_times().back(), 12000u);
    run.send(run.g01(160, 0, 3, 3, kYOff));
    run.run_until_acks(1, 5);
    run.board.run_for_seconds(0.1);
    EXPECT_EQ(run.servo.high_times().back(), 16008u);
}

}  // namespace
}  // namespace avrbench
