// Seed 001's drive board firmware (firmware/printer3d_drive) on its board
// (bench/boards/printer3d-drive-seed001.yaml, the unipolar stepper with sense
// resistors on ADC0/ADC1), driven through its STEP/DIR/ENABLE pins as the
// interpolator would. Expected values: the digest's acceptance checks
// (../shared/seeds/digests/seed_001_3dprinter.md §10) and §9's defects.
// Each test runs under ctest's 300 s wall-clock limit (tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "periph/adc/Adc.hpp"
#include "parts/HybridStepper.hpp"
#include "parts/ThermalPlant.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"

namespace avrbench {
namespace {

struct DriveRun {
    Board board;
    Mcu& mcu;
    HybridStepper& motor;
    std::vector<Adc::Sample> samples;
    explicit DriveRun(const std::string& firmware = "printer3d_drive")
        : board(load_board_file(test::source_path("bench/boards/printer3d-drive-seed001.yaml")),
                {{"drive", test::firmware(firmware)}}),
          mcu(board.mcu("drive")),
          motor(board.part_as<HybridStepper>("motor")) {
        mcu.adc().on_sample([this](const Adc::Sample& s) { samples.push_back(s); });
        board.drive_pin("enable", true);
        board.drive_pin("dir", true);
        board.drive_pin("step", false);
        board.run_for_seconds(0.01);
    }
    // One STEP pulse: 10 us high, then `gap_s` low.
    void step(double gap_s = 0.005) {
        board.drive_pin("step", true);
        board.run_for_seconds(10e-6);
        board.drive_pin("step", false);
        board.run_for_seconds(gap_s);
    }
    unsigned coils() { return mcu.pin("PB0").level() | mcu.pin("PB1").level() << 1 | mcu.pin("PB2").level() << 2 | mcu.pin("PB3").level() << 3; }
    std::int32_t position() const {
        const auto b = mcu.read_ram("position", 4);
        return static_cast<std::int32_t>(b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<std::uint32_t>(b[3]) << 24));
    }
};

TEST(Printer3dDrive, RisingStepEdgesWalkTheCoilSequenceBothWays) {
    DriveRun run;
    // §10.1: 0x05 -> 0x06 -> 0x0A -> 0x09 -> 0x05 with DIR = 1; reversed with DIR = 0.
    EXPECT_EQ(run.mcu.read_ram_u8("motor_state"), 0x05);
    std::vector<unsigned> forward, backward;
    for (int i = 0; i < 4; ++i) {
        run.step();
        forward.push_back(run.mcu.read_ram_u8("motor_state"));
        // The coils never carry a phase the state does not (the chopper only removes).
        EXPECT_EQ(run.coils() & ~forward.back(), 0u);
    }
    EXPECT_EQ(forward, (std::vector<unsigned>{0x06, 0x0A, 0x09, 0x05}));
    run.board.drive_pin("dir", false);
    run.board.run_for_seconds(0.001);
    for (int i = 0; i < 4; ++i) {
        run.step();
        backward.push_back(run.mcu.read_ram_u8("motor_state"));
    }
    EXPECT_EQ(backward, (std::vector<unsigned>{0x09, 0x0A, 0x06, 0x05}));
    EXPECT_EQ(run.position(), 0);  // §10.3: net position = CW - CCW
    // Falling edges do nothing: a step is the rising edge only.
    run.board.drive_pin("step", true);
    run.board.run_for_seconds(0.001);
    const auto before = run.mcu.read_ram_u8("motor_state");
    run.board.drive_pin("step", false);
    run.board.run_for_seconds(0.001);
    EXPECT_EQ(run.mcu.read_ram_u8("motor_state"), before);
}

TEST(Printer3dDrive, DisabledTheCoilsDropAndStepsAreIgnored) {
    DriveRun run;
    run.step();
    run.board.drive_pin("enable", false);
    run.board.run_for_seconds(0.001);
    EXPECT_EQ(run.coils(), 0u);  // §10.2, the safety loop
    const auto state = run.mcu.read_ram_u8("motor_state");
    for (int i = 0; i < 3; ++i) run.step();
    EXPECT_EQ(run.mcu.read_ram_u8("motor_state"), state);
    EXPECT_EQ(run.coils(), 0u);
    EXPECT_EQ(run.position(), 1);
}

TEST(Printer3dDrive, ConversionsEvery204UsAlternateTheSensePairsAndChop) {
    DriveRun run;
    for (int i = 0; i < 200; ++i) run.step(0.002);  // 500 steps/s, 150 rpm, 0.4 s
    // §10.5: Timer1 compare every 16 MHz / 64 / 51 = 204 us = 3264 cycles,
    // one conversion per compare, ADC0 and ADC1 in turn.
    ASSERT_GT(run.samples.size(), 1000u);
    for (std::size_t i = 10; i < 200; ++i) {
        EXPECT_EQ(run.samples[i].cycle - run.samples[i - 1].cycle, 3264u) << i;
        EXPECT_NE(run.samples[i].channel, run.samples[i - 1].channel) << i;
    }
    // The chopper holds the current near its limit: ADCH 101 = 1.973 V across
    // 2.2 ohm is 0.897 A; unchopped the half-winding would reach 12 V / (6.8 +
    // 2.2) ohm = 1.333 A with tau = L / R = 8 mH / 9 ohm = 0.889 ms. A pair is
    // sampled every 2 * 204 us, and its conversion ends 13 ADC clocks (104 us)
    // after the sample, so the current may rise for up to 512 us past the
    // limit: 1.333 - (1.333 - 0.897) * exp(-0.512 / 0.889) = 1.088 A.
    EXPECT_GT(run.mcu.read_ram_u16("chops"), 0u);
    double peak_a = 0;
    run.motor.on_stall([](const HybridStepper::StallEvent&) {});
    for (int i = 0; i < 40; ++i) {
        run.board.run_for_seconds(0.0005);
        run.motor.sync();
        peak_a = std::max({peak_a, std::abs(run.motor.phase_current(0)), std::abs(run.motor.phase_current(1))});
    }
    EXPECT_LT(peak_a, 1.088);
    EXPECT_GT(peak_a, 0.897);  // it does reach the limit
    EXPECT_EQ(run.motor.lost_steps(), 0);
}

TEST(Printer3dDrive, TheListingAsPrintedNeverConverts) {
    // Digest §9.1-9.3: the trigger is Timer0's compare match, Timer0 never
    // runs, so no conversion ever starts; with no samples the chopper never
    // acts and the holding current goes to the unchopped 1.33 A.
    DriveRun run("printer3d_drive_thesis");
    run.step();
    run.board.run_for_seconds(0.5);
    EXPECT_TRUE(run.samples.empty());
    EXPECT_EQ(run.mcu.read_ram_u16("samples"), 0u);
    run.motor.sync();
    const double i = std::max(std::abs(run.motor.phase_current(0)), std::abs(run.motor.phase_current(1)));
    EXPECT_NEAR(i, 12.0 / (6.8 + 2.2), 0.05);
    // The steps themselves still work.
    EXPECT_EQ(run.mcu.read_ram_u8("motor_state"), 0x06);
    // The hot-end control never runs either: no temperature sample, the
    // heater's OCR2 stays 0 (fast PWM: a 1/256 pulse every 2.048 ms), and
    // TEMP_OK (PD6) keeps the level PORTD = 0xFF gave it before DDRD made it
    // an output - high, "temperature OK", from reset on, with no heating.
    EXPECT_EQ(run.mcu.read_ram_u16("temperature_samples"), 0u);
    EXPECT_TRUE(run.mcu.pin("PD6").level());
}

TEST(Printer3dDrive, TheListingWithItsTriggerFixedHoldsTheHeaterFullOn) {
    // Digest §9.4: with conversions running (only §9.1-9.3 fixed), ADCH read
    // into an int8_t is at most 127, so the error 190 - ADCH is at least 63
    // and the PID output 200 e + ... is clamped to 255: the heater is on 100 %
    // and TEMP_OK (|e| < 5) never goes high, whatever the thermistor reads.
    DriveRun run("printer3d_drive_thesis_triggered");
    test::PinLog heater(run.mcu, "PD7"), temp_ok(run.mcu, "PD6");
    run.board.run_for_seconds(0.1);
    // Every third conversion of one per 204 us is a temperature sample.
    EXPECT_NEAR(run.mcu.read_ram_u16("temperature_samples"), run.mcu.seconds() / (3 * 204e-6), 2.0);
    EXPECT_TRUE(heater.falls().empty());       // OCR2 = 255: constantly high (§10.4)
    EXPECT_TRUE(run.mcu.pin("PD7").level());
    EXPECT_FALSE(run.mcu.pin("PD6").level());
    EXPECT_TRUE(temp_ok.rises().empty());
}

// The run itself says what §9.1-9.3 do to the hot end, on the drive board
// with the listing's hot end attached (printer3d-drive-hotend-seed001.yaml):
// the heater's 1/256 pulses heat a body whose thermistor is never read, so
// the plant reports heating-unmonitored once its `unmonitored_after` (5 s)
// has passed: at 5 s = 80 000 000 cycles of 16 MHz, on the plant's 100 ms
// sample grid. The build with the trigger fixed reads its sensor (no such
// finding, whatever else it gets wrong: §9.4), and so does the heater MCU's
// own firmware on the same pins. TEMP_OK is wired to the plant's `ready`
// check: the listing holds it high on a cold hot end (the pull-up PORTD =
// 0xFF set before DDRD, §9.x), a ready-while-cold finding at the plant's
// first sample, 100 ms = 1 600 000 cycles.
std::vector<Finding> hot_end_findings(const std::string& firmware, const FindingKind& kind) {
    Board board(load_board_file(test::source_path("bench/boards/printer3d-drive-hotend-seed001.yaml")),
                {{"drive", test::firmware(firmware)}});
    board.run_for_seconds(6.0);
    std::vector<Finding> out;
    for (const Finding& f : board.findings()) {
        if (f.kind == kind) out.push_back(f);
    }
    return out;
}

TEST(Printer3dDrive, TheListingHeatsAnUnreadHotEndAndTheRunReportsIt) {
    const auto unread = hot_end_findings("printer3d_drive_thesis", ThermalPlant::kHeatingUnmonitored);
    ASSERT_EQ(unread.size(), 1u);
    EXPECT_EQ(unread[0].source, "hotend");
    EXPECT_EQ(unread[0].cycle, 80'000'000u);
    EXPECT_TRUE(hot_end_findings("printer3d_drive_thesis_triggered", ThermalPlant::kHeatingUnmonitored).empty());
    EXPECT_TRUE(hot_end_findings("printer3d_heater", ThermalPlant::kHeatingUnmonitored).empty());
}

TEST(Printer3dDrive, TheListingsTempOkOnAColdHotEndIsReportedByTheRun) {
    const auto ready = hot_end_findings("printer3d_drive_thesis", ThermalPlant::kReadyWhileCold);
    ASSERT_EQ(ready.size(), 1u);
    EXPECT_EQ(ready[0].cycle, 1'600'000u);
    EXPECT_TRUE(hot_end_findings("printer3d_drive_thesis_triggered", ThermalPlant::kReadyWhileCold).empty());
    EXPECT_TRUE(hot_end_findings("printer3d_heater", ThermalPlant::kReadyWhileCold).empty());
}

// §9.7: the listing's INT0 routine is ISR_NOBLOCK, so the ADC routine can
// run inside it, between its read of `chopped` and its write of PORTB: the
// step then switches on a pair the chopper has just switched off, until
// that pair's next sample (one in three conversions: 612 us). With the
// conversions running and ADCH read as 0..255 (printer3d_drive_thesis_counts:
// the chopper chops the standstill current, 12 V over the windings and the
// 2.2 ohm sense resistor well above the limit of 100 counts), a coil pin
// high while `chopped` holds its pair is the race, seen at the instant of
// the PORTB write that made it. The fixed firmware's INT0 routine blocks
// interrupts: never.
struct ChopRace {
    unsigned glitches = 0;
    std::set<std::string> where;  // the PC of each glitch's PORTB write, by symbol
};

ChopRace chopped_pairs_switched_on(const std::string& firmware) {
    DriveRun run(firmware);
    ChopRace race;
    for (const char* coil : {"PB0", "PB1", "PB2", "PB3"}) {
        const unsigned bit = 1u << (coil[2] - '0');
        run.mcu.pin(coil).on_change([&run, &race, bit](Cycle, bool level) {
            if (!level || (run.mcu.read_ram_u8("chopped") & bit) == 0) return;
            ++race.glitches;
            race.where.insert(run.mcu.describe_pc(run.mcu.pc_bytes()));
        });
    }
    // 3000 steps at about 500 steps/s, the gap varied by 1..7 x 13 us so the
    // steps fall on every phase of the conversions' 204 us grid.
    for (int i = 0; i < 3000; ++i) run.step(0.002 + 13e-6 * (1 + i % 7));
    return race;
}

TEST(Printer3dDrive, TheListingsNonBlockingStepRoutineUndoesAChop) {
    const ChopRace literal = chopped_pairs_switched_on("printer3d_drive_thesis_counts");
    EXPECT_GT(literal.glitches, 0u);
    for (const std::string& pc : literal.where) EXPECT_NE(pc.find("__vector_1"), std::string::npos) << pc;  // INT0_vect
    EXPECT_EQ(chopped_pairs_switched_on("printer3d_drive").glitches, 0u);
}

// printer3d_drive_thesis_counts: the listing with §9.1-9.4 fixed (the
// conversions run, ADCH read as 0..255), so the PID's own defects show.
// Cold, the NTC in the lower leg reads 5 V x 100 k / (100 k + 891.7) = 4.956 V
// = 253 of 256 counts: error = 190 - 253 = -63 on every sample, the output
// negative, the heater at its 1/256 minimum - until errorSum (§9.6: an
// int16_t with no bound) passes -32 768: -63 x 521 = -32 823 wraps to
// +32 713, and 200 x -63 + 32 713 = 20 113 is full heat (OCR2 = 255).
TEST(Printer3dDrive, TheCountsPidsErrorSumWrapsAndHeatsAColdHotEnd) {
    Board board(load_board_file(test::source_path("bench/boards/printer3d-drive-hotend-seed001.yaml")),
                {{"drive", test::firmware("printer3d_drive_thesis_counts")}});
    Mcu& drive = board.mcu("drive");
    const auto error_sum = [&] { return static_cast<std::int16_t>(drive.read_ram_u16("errorSum")); };
    double t = 0;
    while (error_sum() <= 0 && t < 1.0) board.run_until_seconds(t += 0.0005);
    const unsigned samples = drive.read_ram_u16("temperature_samples");
    EXPECT_EQ(samples, 521u);
    EXPECT_EQ(error_sum(), static_cast<std::int16_t>(-63 * 521 + 65536));
    constexpr std::uint32_t kOcr2 = 0x23 + 0x20;  // ATmega32: OCR2 at I/O 0x23
    EXPECT_EQ(drive.peek(kOcr2), 255u);
}

// §9.5: error = 190 - counts, and the counts fall as the NTC heats (lower
// leg), so above the temperature that reads 190 counts (about 134.5 degC)
// the error is positive and grows with every degree: the hotter, the more
// heat. From 150 degC the firmware's own last error rises with the block's
// temperature, and the hot end runs to its maximum (lowered to 200 degC
// here, so the run is short).
TEST(Printer3dDrive, TheCountsPidHeatsHarderTheHotterItGets) {
    BoardSpec spec = load_board_file(test::source_path("bench/boards/printer3d-drive-hotend-seed001.yaml"));
    for (auto& part : spec.parts) {
        if (part.name != "hotend") continue;
        part.params.push_back({"initial", "150degC", part.location});
        part.params.push_back({"max_temperature", "200degC", part.location});
    }
    Board board(std::move(spec), {{"drive", test::firmware("printer3d_drive_thesis_counts")}});
    Mcu& drive = board.mcu("drive");
    auto& plant = board.part_as<ThermalPlant>("hotend");
    const auto error = [&] { return static_cast<std::int16_t>(drive.read_ram_u16("previousError")); };
    std::vector<std::pair<double, int>> sensor_and_error;  // every 10 s
    for (double t = 10; t <= 120 && board.findings().empty(); t += 10) {
        board.run_until_seconds(t);
        sensor_and_error.push_back({plant.sensor_degC(), error()});
    }
    ASSERT_GE(sensor_and_error.size(), 3u);
    for (std::size_t i = 1; i < sensor_and_error.size(); ++i) {
        EXPECT_GT(sensor_and_error[i].first, sensor_and_error[i - 1].first) << "sample " << i;
        EXPECT_GE(sensor_and_error[i].second, sensor_and_error[i - 1].second) << "sample " << i;
        EXPECT_GT(sensor_and_error[i].second, 0) << "sample " << i;
    }
    std::vector<Finding> overheat;
    for (const Finding& f : board.findings()) {
        if (f.kind == ThermalPlant::kOverheat) overheat.push_back(f);
    }
    ASSERT_EQ(overheat.size(), 1u);
    EXPECT_NE(overheat[0].detail.find("above the plant's maximum of 200.0 degC"), std::string::npos) << overheat[0].detail;
}

}  // namespace
}  // namespace avrbench
