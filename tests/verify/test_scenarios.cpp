// The regression workflow end to end through the CLI: a firmware change that
// shifts timing fails its scenario with a diff naming the channel and the
// first divergent edge; `avrbench golden update` accepts it; the next check
// passes. Plus JUnit output and sharding.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "support/Paths.hpp"
#include "trace/TimelineText.hpp"
#include "core/Errors.hpp"
#include "verify/Scenario.hpp"

#include <cmath>
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

namespace fs = std::filesystem;
const std::string kScenarioCli = ::avrbench::test::cli();

// A blink scenario in `dir` running `firmware`, with its golden in `dir`.
fs::path write_blink_scenario(const fs::path& dir, const std::string& name, const std::string& firmware) {
    const fs::path path = dir / (name + ".yaml");
    std::ofstream(path) << "name: " << name << "\n"
                        << "board: " << test::source_path("bench/boards/arduino-uno.yaml") << "\n"
                        << "firmware: {uno: " << firmware << "}\n"
                        << "steps:\n  - delay: 20ms\n"
                        << "expect:\n  - findings: 0\n"
                        << "golden: " << name << ".timeline\n";
    return path;
}

std::string check(const fs::path& scenario, const fs::path& dir, int* exit_code, const std::string& extra = "") {
    const auto r = test::run_command(kScenarioCli + " check " + scenario.string() + " --firmware-dir " + ::avrbench::test::firmware_dir() +
                                         " --report-dir " + (dir / "reports").string() + extra, dir);
    *exit_code = r.exit_code;
    return r.out + r.err;
}

TEST(Scenarios, ShiftedTimerFailsNamingTheChannelAndFirstEdgeThenGoldenUpdateAccepts) {
    const auto dir = test::scratch_dir("scenario-regression");
    // The golden made from the committed blink firmware (OCR1A = 249)...
    fs::copy_file(test::source_path("golden/blink_timer1.timeline"), dir / "blink.timeline");
    // ...checked against the same source built with OCR1A = 250.
    const fs::path scenario = write_blink_scenario(dir, "blink", "blink_timer1_ocr250");
    int code = 0;
    const std::string out = check(scenario, dir, &code, " --junit " + (dir / "junit.xml").string());
    EXPECT_EQ(code, 1) << out;
    // OC1A (PB1) toggles at the first compare match, (249 + 1) * 64 = 16000
    // cycles after Timer1 starts in the golden; with OCR1A = 250 one timer
    // count (64 cycles) later, give or take the few cycles by which the
    // rebuilt start-up code moves the timer start. PB1's edge is the earliest
    // divergence (the ISR's PB5 edge follows it).
    const ParsedTimeline golden = read_timeline_text((dir / "blink.timeline").string());
    const long pb1 = golden.timeline.find("uno", "PB1");
    ASSERT_GE(pb1, 0);
    const Cycle golden_edge = changes_of(golden.timeline, static_cast<SignalId>(pb1)).at(1).cycle;
    EXPECT_NE(out.find("first divergence: uno.PB1 at "), std::string::npos) << out;
    EXPECT_NE(out.find("(cycle " + std::to_string(golden_edge) + ")"), std::string::npos) << out;
    EXPECT_NE(out.find("expected 1 at cycle " + std::to_string(golden_edge)), std::string::npos) << out;
    const auto at = out.find("actual   1 at cycle ");
    ASSERT_NE(at, std::string::npos) << out;
    const auto actual_edge = static_cast<Cycle>(std::stol(out.substr(at + 20)));
    EXPECT_GE(actual_edge, golden_edge + 64 - 8);
    EXPECT_LE(actual_edge, golden_edge + 64 + 8);
    // The per-channel table lists both toggling pins as differing.
    EXPECT_NE(out.find("uno.PB5"), std::string::npos) << out;
    EXPECT_TRUE(fs::exists(dir / "reports" / "blink.html"));
    const std::string junit = test::slurp(dir / "junit.xml");
    EXPECT_NE(junit.find("<testsuite name=\"avrbench\" tests=\"1\" failures=\"1\""), std::string::npos) << junit;
    EXPECT_NE(junit.find("<failure message=\"golden: uno.PB1 diverges"), std::string::npos) << junit;

    // Accept the change explicitly; the check passes afterwards.
    const auto update = test::run_command(kScenarioCli + " golden update " + scenario.string() + " --firmware-dir " +
                                              ::avrbench::test::firmware_dir(), dir);
    ASSERT_EQ(update.exit_code, 0) << update.out << update.err;
    // The new golden toggles every (250 + 1) * 64 = 16064 cycles.
    EXPECT_NE(test::slurp(dir / "blink.timeline").find("*9 +16064 0 +16064 1"), std::string::npos)
        << test::slurp(dir / "blink.timeline");
    const std::string again = check(scenario, dir, &code);
    EXPECT_EQ(code, 0) << again;
    EXPECT_NE(again.find("PASS blink"), std::string::npos) << again;
}

// A plain check streams the run into its comparison (and its VCD); with a
// report folder the run is held whole. Both must judge alike, passing and
// failing, to the letter of the report, and write the same VCD.
TEST(Scenarios, AStreamedCheckJudgesAsTheRunHeldWhole) {
    const auto dir = test::scratch_dir("scenario-streamed");
    fs::copy_file(test::source_path("golden/blink_timer1.timeline"), dir / "blink.timeline");
    for (const std::string firmware : {"blink_timer1", "blink_timer1_ocr250"}) {
        const fs::path path = write_blink_scenario(dir, "blink", firmware);
        const ScenarioSpec spec = load_scenario(path.string(), ::avrbench::test::firmware_dir());
        ScenarioRunOptions streamed_options;
        streamed_options.vcd_dir = (dir / "streamed").string();
        fs::create_directories(streamed_options.vcd_dir);
        const ScenarioResult streamed = run_scenario(spec, streamed_options);
        ScenarioRunOptions held_options;
        held_options.vcd_dir = (dir / "held").string();
        held_options.report_dir = (dir / "held").string();
        fs::create_directories(held_options.vcd_dir);
        const ScenarioResult held = run_scenario(spec, held_options);
        const std::string vcd = test::slurp(dir / "streamed" / "blink.vcd");
        EXPECT_EQ(vcd, test::slurp(dir / "held" / "blink.vcd"));
        EXPECT_EQ(test::slurp(dir / "streamed" / "blink.gtkw"), test::slurp(dir / "held" / "blink.gtkw"));
        // Not empty: the LED's pin and the UART are declared, and PB1 toggles.
        EXPECT_NE(vcd.find("$var wire 1 "), std::string::npos);
        EXPECT_NE(vcd.find("PB1"), std::string::npos);
        EXPECT_TRUE(streamed.streamed);
        EXPECT_FALSE(held.streamed);
        // The committed golden is this firmware's; OCR1A = 250 moves every edge.
        EXPECT_EQ(streamed.passed, firmware == "blink_timer1") << streamed.text();
        EXPECT_EQ(held.passed, streamed.passed);
        ASSERT_TRUE(streamed.comparison.has_value());
        ASSERT_TRUE(held.comparison.has_value());
        EXPECT_EQ(streamed.comparison->report(), held.comparison->report());
        EXPECT_EQ(streamed.failures, held.failures);
        ASSERT_EQ(streamed.comparison->channels.size(), held.comparison->channels.size());
        for (std::size_t i = 0; i < held.comparison->channels.size(); ++i) {
            EXPECT_EQ(streamed.comparison->channels[i].actual_changes, held.comparison->channels[i].actual_changes)
                << held.comparison->channels[i].signal;
        }
    }
}

// `golden update` streams the same way: the file written from the streamed
// run is the one written from the run held whole, byte for byte.
TEST(Scenarios, AStreamedGoldenUpdateWritesTheSameFileAsTheRunHeldWhole) {
    const auto dir = test::scratch_dir("scenario-streamed-update");
    const fs::path path = write_blink_scenario(dir, "blink", "blink_timer1");
    const ScenarioSpec spec = load_scenario(path.string(), ::avrbench::test::firmware_dir());
    ScenarioRunOptions update;
    update.update_golden = true;
    const ScenarioResult streamed = run_scenario(spec, update);
    EXPECT_TRUE(streamed.streamed);
    const std::string from_stream = test::slurp(dir / "blink.timeline");
    update.report_dir = (dir / "reports").string();
    fs::create_directories(update.report_dir);
    const ScenarioResult held = run_scenario(spec, update);
    EXPECT_FALSE(held.streamed);
    const std::string from_held = test::slurp(dir / "blink.timeline");
    EXPECT_EQ(from_stream, from_held);
    // Not empty: Timer1's OC1A on PB1 every (249 + 1) * 64 = 16000 cycles.
    EXPECT_NE(from_stream.find("+16000 0 +16000 1"), std::string::npos) << from_stream;
}

TEST(Scenarios, CheckNeverWritesAGolden) {
    const auto dir = test::scratch_dir("scenario-no-golden");
    const fs::path scenario = write_blink_scenario(dir, "fresh", "blink_timer1");
    int code = 0;
    const std::string out = check(scenario, dir, &code);
    EXPECT_EQ(code, 1) << out;
    EXPECT_NE(out.find("no golden timeline at"), std::string::npos) << out;
    EXPECT_NE(out.find("avrbench golden update"), std::string::npos) << out;
    EXPECT_FALSE(fs::exists(dir / "fresh.timeline"));
}

TEST(Scenarios, ShardingSplitsTheScenarioList) {
    const auto dir = test::scratch_dir("scenario-shards");
    const fs::path a = write_blink_scenario(dir, "first", "blink_timer1");
    const fs::path b = write_blink_scenario(dir, "second", "blink_timer1");
    for (const auto& s : {a, b}) {
        ASSERT_EQ(test::run_command(kScenarioCli + " golden update " + s.string() + " --firmware-dir " + ::avrbench::test::firmware_dir(), dir)
                      .exit_code,
                  0);
    }
    const auto shard1 = test::run_command("GTEST_TOTAL_SHARDS=2 GTEST_SHARD_INDEX=1 " + kScenarioCli + " check " + a.string() +
                                              " " + b.string() + " --firmware-dir " + ::avrbench::test::firmware_dir(), dir);
    EXPECT_EQ(shard1.exit_code, 0) << shard1.out;
    EXPECT_EQ(shard1.out.find("first"), std::string::npos) << shard1.out;
    EXPECT_NE(shard1.out.find("PASS second"), std::string::npos) << shard1.out;
    EXPECT_NE(shard1.out.find("1 passed, 0 failed"), std::string::npos) << shard1.out;
}

TEST(Scenarios, MalformedScenarioIsOneLineWithExitCode2) {
    const auto dir = test::scratch_dir("scenario-bad");
    const fs::path path = dir / "bad.yaml";
    std::ofstream(path) << "board: " << test::source_path("bench/boards/arduino-uno.yaml") << "\n"
                        << "firmware: {uno: blink_timer1}\n"
                        << "steps:\n  - dance: 3\n";
    const auto r = test::run_command(kScenarioCli + " check " + path.string() + " --firmware-dir " + ::avrbench::test::firmware_dir(), dir);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, "avrbench: error: " + path.string() +
                         ":4: unknown step 'dance' (known: delay, inject_fault, press, release, release_input, send, send_file, "
                         "set_input, turn, wait_for_text, wait_idle, wait_pin)\n");
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// A wait wakes on the edge it waits for, at its cycle: blink_timer1's first
// OC1A toggle (PB1 high) is in the committed golden; the scenario ends with
// the wait, so its simulated time is the edge's, within one step of the core
// after it (the compare match also raises the interrupt: the 4-cycle response
// plus the instruction in progress, at most 8 cycles), not the next poll (a
// poll every 10 us, 160 cycles, ended it at 16160).
TEST(Scenarios, WaitPinEndsAtTheEdgesCycle) {
    const auto dir = test::scratch_dir("scenario-wait-pin");
    const fs::path path = dir / "wait.yaml";
    std::ofstream(path) << "name: wait\n"
                        << "board: " << test::source_path("bench/boards/arduino-uno.yaml") << "\n"
                        << "firmware: {uno: blink_timer1}\n"
                        << "time_limit: 10ms\n"
                        << "steps:\n  - wait_pin: {pin: uno.PB1, level: 1}\n";
    const ParsedTimeline golden = read_timeline_text(test::source_path("golden/blink_timer1.timeline"));
    const long pb1 = golden.timeline.find("uno", "PB1");
    ASSERT_GE(pb1, 0);
    const Cycle edge = changes_of(golden.timeline, static_cast<SignalId>(pb1)).at(1).cycle;
    const ScenarioResult r = run_scenario(load_scenario(path.string(), ::avrbench::test::firmware_dir()), {});
    ASSERT_TRUE(r.passed) << r.text();
    const auto end_cycle = static_cast<Cycle>(std::llround(r.simulated_s * 16e6));
    EXPECT_GE(end_cycle, edge);
    EXPECT_LE(end_cycle, edge + 8) << "the wait ended " << end_cycle - edge << " cycles after the edge";
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// A timing bound one cycle under blink_timer1's 28-cycle ISR fails, naming
// the vector, what it took and the bound (tests/scenarios/blink_timer1_timing.yaml
// holds the hand count).
TEST(Scenarios, AnIsrOverItsCycleBoundFailsWithTheMeasuredTime) {
    const auto dir = test::scratch_dir("scenario-isr-bound");
    const fs::path path = dir / "isr.yaml";
    std::ofstream(path) << "name: isr\n"
                        << "board: " << test::source_path("bench/boards/arduino-uno.yaml") << "\n"
                        << "firmware: {uno: blink_timer1}\n"
                        << "steps:\n  - delay: 10ms\n"
                        << "expect:\n  - isr: {vector: 11, max_cycles: 27}\n  - stack: {min_headroom_bytes: 2041}\n";
    const ScenarioResult r = run_scenario(load_scenario(path.string(), ::avrbench::test::firmware_dir()), {});
    EXPECT_FALSE(r.passed);
    ASSERT_EQ(r.expectation_failures.size(), 2u) << r.text();
    EXPECT_NE(r.expectation_failures[0].find("vector 11 (TIMER1_COMPA) took up to 28 cycles (median 28), expected at most 27"),
              std::string::npos)
        << r.expectation_failures[0];
    EXPECT_NE(r.expectation_failures[1].find("within 2040 bytes"), std::string::npos) << r.expectation_failures[1];
}

TEST(Scenarios, ATimingBoundForAnUnknownMcuIsAFileLineError) {
    const auto dir = test::scratch_dir("scenario-isr-mcu");
    const fs::path path = dir / "isr.yaml";
    std::ofstream(path) << "name: isr\n"
                        << "board: " << test::source_path("bench/boards/arduino-uno.yaml") << "\n"
                        << "firmware: {uno: blink_timer1}\n"
                        << "expect:\n  - isr: {vector: 11, mcu: mega, max_cycles: 27}\n";
    try {
        load_scenario(path.string(), ::avrbench::test::firmware_dir());
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("isr.yaml:5"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("no MCU 'mega'"), std::string::npos) << e.what();
    }
}

// A part signal held to a band from a time on (`signal`): the card print
// (firmware/boards/sd_print) takes X out to 120 mm on the square's first
// side (100 mm start + 20 mm), so a band ending at 119 mm from 0 s fails
// naming the highest value; after the print X is back at 100 mm: four 20 mm
// sides at 1200 mm/min (4 s), the 28.3 mm diagonal at 600 (2.83 s) and back
// at 3000 (0.57 s) end about 7.7 s in (0.3 s to boot and take the lines),
// so a band around 100 mm from 7.8 s passes. Load errors name the line.
TEST(Scenarios, ASignalOutsideItsBandFailsWithTheValueAndTime) {
    const auto dir = test::scratch_dir("scenario-signal");
    auto scenario = [&](const std::string& expect) {
        const fs::path path = dir / "signal.yaml";
        std::ofstream(path) << "name: signal\n"
                            << "board: " << test::source_path("tests/scenarios/boards/ramps-sd-square.yaml") << "\n"
                            << "firmware: {mega: sd_print}\ntime_limit: 20s\n"
                            << "steps:\n  - wait_for_text: start\n  - send: M23 square.gco\n  - send: M24\n"
                            << "  - wait_for_text: Done printing file\n  - wait_idle: 100ms\n"
                            << "expect:\n  - " << expect << "\n";
        return path.string();
    };
    const ScenarioResult over = run_scenario(load_scenario(scenario("signal: {name: x.position_mm, max: 119}"),
                                                           ::avrbench::test::firmware_dir()), {});
    ASSERT_EQ(over.expectation_failures.size(), 1u) << over.text();
    EXPECT_NE(over.expectation_failures[0].find("x.position_mm went up to 120 at "), std::string::npos)
        << over.expectation_failures[0];
    const ScenarioResult after = run_scenario(load_scenario(scenario("signal: {name: x.position_mm, min: 99.99, max: 100.01, from: 7.8s}"),
                                                            ::avrbench::test::firmware_dir()), {});
    EXPECT_TRUE(after.passed) << after.text();
    try {
        load_scenario(scenario("signal: {name: x.position_mm}"), ::avrbench::test::firmware_dir());
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("signal.yaml:12: 'signal' needs min, max or both"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace avrbench
