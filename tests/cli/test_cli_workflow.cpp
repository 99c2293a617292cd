// The CI workflow as a firmware team uses it: batches of scenarios with one
// broken file, serial I/O on boards, output paths, golden updates.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <filesystem>
#include <fstream>

#include "support/Paths.hpp"
#include "support/RunCommand.hpp"
#include "trace/VcdReader.hpp"

namespace avrbench {
namespace {

namespace fs = std::filesystem;
const std::string kWorkflowCli = ::avrbench::test::cli();
const std::string kFw = std::string(" --firmware-dir ") + ::avrbench::test::firmware_dir();

fs::path write(const fs::path& path, const std::string& text) {
    std::ofstream(path) << text;
    return path;
}

std::string uno() { return test::source_path("bench/boards/arduino-uno.yaml"); }
std::string cnc() { return test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml"); }

TEST(CheckBatch, ABrokenScenarioIsOneErrorResultAndTheOthersStillRun) {
    const auto dir = test::scratch_dir("batch");
    const fs::path good = write(dir / "good.yaml", "board: " + uno() + "\nfirmware: {uno: blink_timer1}\nsteps:\n  - delay: 5ms\n"
                                                   "expect:\n  - findings: 0\n");
    // Line 6: an axis the board does not have.
    const fs::path bad = write(dir / "bad.yaml", "board: " + cnc() + "\nfirmware: {uno: blink_timer1}\nsteps:\n  - delay: 5ms\n"
                                                 "expect:\n  - steps: {axis: w, count: 3}\n");
    const fs::path also_good = write(dir / "also_good.yaml", "board: " + uno() + "\nfirmware: {uno: blink_timer1}\n");
    const fs::path junit = dir / "j.xml";
    const auto r = test::run_command(kWorkflowCli + " check " + good.string() + " " + bad.string() + " " + also_good.string() +
                                         kFw + " --junit " + junit.string(), dir);
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;  // an input error in the batch
    EXPECT_NE(r.out.find("PASS good"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("PASS also_good"), std::string::npos) << r.out;
    const std::string where = bad.string() + ":6: the board has no axis 'w' (axes: x, y, z)";
    EXPECT_NE(r.out.find("ERROR bad\n  " + where), std::string::npos) << r.out;
    EXPECT_NE(r.err.find(where), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("2 passed, 1 failed"), std::string::npos) << r.out;
    const std::string xml = test::slurp(junit);
    EXPECT_NE(xml.find("tests=\"3\" failures=\"0\" errors=\"1\""), std::string::npos) << xml;
    EXPECT_NE(xml.find("<error message=\"" + where), std::string::npos) << xml;
}

// check --vcd-dir: each scenario's waveforms beside its verdict, the run as
// `run --vcd` would record it. blink_timer1 toggles PB5 every 1 ms (Timer1
// CTC, (249 + 1) x 64 cycles at 16 MHz): 20 ms give 20 edges, 19 when the
// last falls after the run's end (the boot takes a few microseconds).
TEST(CheckBatch, VcdDirHoldsEachScenariosWaveforms) {
    const auto dir = test::scratch_dir("vcd-dir");
    const fs::path blink = write(dir / "blink.yaml", "board: " + uno() + "\nfirmware: {uno: blink_timer1}\nsteps:\n  - delay: 20ms\n");
    const auto r = test::run_command(kWorkflowCli + " check " + blink.string() + kFw + " --vcd-dir " + (dir / "waves").string(), dir);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("  waveforms: " + (dir / "waves/blink.vcd").string() + " (gtkwave " + (dir / "waves/blink.gtkw").string() + ")"),
              std::string::npos)
        << r.out;
    const VcdDump dump = read_vcd((dir / "waves/blink.vcd").string());
    const VcdVariable& led = dump.at("labels.led");  // the UNO's D13 LED, PB5, under its board-file name
    std::size_t edges = 0;
    for (std::size_t i = 1; i < led.changes.size(); ++i) edges += led.changes[i].value != led.changes[i - 1].value;
    EXPECT_GE(edges, 19u);
    EXPECT_LE(edges, 20u);
    EXPECT_TRUE(fs::exists(dir / "waves/blink.gtkw"));
}

// Every reference is checked before anything is simulated: the error comes
// even though the bad expectation follows a step that would run 1000 s.
TEST(CheckBatch, ScenarioIsValidatedBeforeAnySimulation) {
    const auto dir = test::scratch_dir("validate");
    struct Case {
        std::string body;
        std::string message;
        bool cnc_board = false;
    };
    const std::vector<Case> cases = {
        {"  - delay: 1000s\n  - wait_pin: {pin: uno.PZ9, level: 1}\n", ":5: atmega328p has no pin 'PZ9' (in 'uno.PZ9')"},
        {"  - delay: 1000s\n  - set_input: {pin: nosuch, level: 1}\n", ":5: 'nosuch' is neither mcu.PIN nor a label"},
        {"  - delay: 1000s\n  - inject_fault: {part: heater, fault: melt}\n", ":5: the board has no part 'heater'"},
        {"  - delay: 1000s\n  - delay: 3 parsecs\n", ":5: delay: unknown unit 'parsecs'"},
        {"  - delay: 1000s\n  - wait_pin: {pin: uno.PB5, level: 2}\n", ":5: level '2' is not 0/low or 1/high"},
        {"  - delay: 1000s\n  - wait_pin: {pin: uno.PB5}\n", ":5: 'wait_pin' needs 'level'"},
        {"  - delay: 1000s\nexpect:\n  - findings: 1e300\n", ":6: findings: '1e300' is outside 0..9007199254740992"},
        {"  - delay: 1000s\nexpect:\n  - findings: [no-such-kind]\n", ":6: unknown finding kind 'no-such-kind'"},
        {"  - delay: 1000s\nexpect:\n  - steps: {axis: x, count: 3}\n", ":6: the board has no axis 'x' (axes: none)"},
        {"  - delay: 1000s\nexpect:\n  - steps: {axis: x, count: 2.5}\n", ":6: count: '2.5' is not a whole number", true},
    };
    int n = 0;
    for (const auto& c : cases) {
        const fs::path path = write(dir / ("s" + std::to_string(n++) + ".yaml"),
                                    "board: " + (c.cnc_board ? cnc() : uno()) + "\nfirmware: {uno: blink_timer1}\nsteps:\n" + c.body);
        const auto r = test::run_command(kWorkflowCli + " check " + path.string() + kFw, dir, 30);
        EXPECT_EQ(r.exit_code, 2) << c.body << r.out << r.err;
        EXPECT_NE(r.err.find(path.string() + c.message), std::string::npos) << c.message << "\n" << r.err;
    }
}

TEST(BoardSerial, UartInAndOutWorkOnABoardWithAndWithoutGcode) {
    const auto dir = test::scratch_dir("board-serial");
    const fs::path in = write(dir / "in.txt", "hello\n");
    const fs::path out = dir / "out.txt";
    const auto r = test::run_command(kWorkflowCli + " run -q --board " + uno() + " " + test::firmware("uart_echo") + " --for 20ms" +
                                         " --uart-in " + in.string() + " --uart-out host=" + out.string(), dir);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    // The firmware's banner, then its echo of what it was sent (firmware/uart_echo).
    EXPECT_EQ(test::slurp(out), "avrbench uart_echo\r\nhello\n");
    // The summary shows the port's traffic and last lines without --gcode.
    EXPECT_NE(r.out.find("serial host 26 bytes from firmware, 6 bytes to firmware; last lines:\n    avrbench uart_echo\n    hello\n"),
              std::string::npos) << r.out;
    const auto bad_port = test::run_command(kWorkflowCli + " run -q --board " + uno() + " " + test::firmware("uart_echo") +
                                                " --for 1ms --uart-out debug=" + out.string(), dir);
    EXPECT_EQ(bad_port.exit_code, 2);
    EXPECT_NE(bad_port.err.find("no serial port 'debug' (ports: host)"), std::string::npos) << bad_port.err;
}

TEST(OutputPaths, BadPathsFailBeforeTheRunWithOneLine) {
    const auto dir = test::scratch_dir("out-paths");
    write(dir / "a_file", "x");
    const std::string run = kWorkflowCli + " run -q --board " + uno() + " " + test::firmware("busy_poll") + " --for 1000s ";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"--vcd /nonexistent/x.vcd", "avrbench: error: --vcd: /nonexistent/x.vcd: the folder /nonexistent does not exist\n"},
        {"--report /nonexistent/r.html", "avrbench: error: --report: /nonexistent/r.html: the folder /nonexistent does not exist\n"},
        {"--vcd " + (dir / "a_file" / "x.vcd").string(),
         "avrbench: error: --vcd: " + (dir / "a_file" / "x.vcd").string() + ": " + (dir / "a_file").string() + " is not a folder\n"},
        {"--vcd " + dir.string(), "avrbench: error: --vcd: " + dir.string() + ": is a folder\n"},
        {"--uart-out /dev/full", "avrbench: error: --uart-out: /dev/full: is not a regular file (a device, FIFO or socket)\n"},
    };
    for (const auto& [option, message] : cases) {
        // 1000 s of busy simulation would take minutes: the 20 s guard
        // proves the check comes first.
        const auto r = test::run_command(run + option, dir, 20);
        EXPECT_EQ(r.exit_code, 2) << option << r.out << r.err;
        EXPECT_EQ(r.err, message);
    }
}

TEST(OutputPaths, ADeviceOrFifoTargetIsRefusedAndLeftInPlace) {
    const auto dir = test::scratch_dir("out-device");
    const fs::path fifo = dir / "fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
    const auto r = test::run_command(kWorkflowCli + " run -q " + test::firmware("blink_timer1") + " --for 1ms --vcd " + fifo.string(), dir, 20);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_TRUE(fs::is_fifo(fifo)) << "the bench removed a file it did not create";
    // As root a character device can be made (mknod c 1 7 is /dev/full);
    // as another user mknod is refused and the FIFO above stands for it.
    const fs::path device = dir / "fd";
    if (::mknod(device.c_str(), S_IFCHR | 0644, makedev(1, 7)) == 0) {
        const auto d = test::run_command(kWorkflowCli + " run -q " + test::firmware("blink_timer1") + " --for 1ms --vcd " + device.string(), dir, 20);
        EXPECT_EQ(d.exit_code, 2) << d.err;
        EXPECT_TRUE(fs::is_character_file(device)) << "the bench removed a device node";
    }
}

TEST(OutputPaths, SummaryToAFullDiskIsAnError) {
    const auto dir = test::scratch_dir("stdout-full");
    const auto r = test::run_command(kWorkflowCli + " run " + test::firmware("blink_timer1") + " --for 1ms > /dev/full", dir, 20);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, "avrbench: error: cannot write to standard output\n");
}

// Ctrl-C (or a CI system's SIGTERM) ends a long run cleanly: what was
// recorded is written, exit 130.
TEST(Interrupt, SigintEndsALongRunWritingWhatWasRecorded) {
    const auto dir = test::scratch_dir("sigint");
    for (const std::string& board : {std::string(""), " --board " + uno()}) {
        const std::string vcd = (dir / "long.vcd").string();
        std::filesystem::remove(vcd);
        // 1000 s of simulation would take many minutes; SIGINT comes after 2 s.
        // busy_poll never idles (blink_timer1's idle loop is skipped: 1000 s in 0.6 s).
        const auto r = test::run_command("timeout --preserve-status -s INT 2 " + kWorkflowCli + " run -q" + board + " " +
                                             test::firmware("busy_poll") + " --for 1000s --vcd " + vcd, dir, 60);
        EXPECT_EQ(r.exit_code, 130) << board << r.err;
        EXPECT_NE(r.err.find("avrbench: interrupted at "), std::string::npos) << r.err;
        const std::string dump = test::slurp(vcd);
        EXPECT_NE(dump.find("$enddefinitions"), std::string::npos) << board;
        EXPECT_NE(r.out.find("simulated"), std::string::npos) << board;
    }
}

// --vcd streams the dump while the run goes (bounded memory); with --report
// too, the run also keeps the signals the report reads, which must not change
// the dump (the demo's job: moves, UART traffic, part signals).
TEST(BoardRun, AReportDoesNotChangeTheStreamedVcd) {
    const auto dir = test::scratch_dir("vcd-streamed");
    const std::string base = kWorkflowCli + " run -q --board arduino-uno-cnc-shield-v3 " + test::firmware("stepdir_test") + " --gcode " +
                             test::source_path("tests/scenarios/jobs/demo_square.gcode") + " --family generic --vcd ";
    const auto streamed = test::run_command(base + (dir / "streamed.vcd").string(), dir, 120);
    const auto whole = test::run_command(base + (dir / "whole.vcd").string() + " --report " + (dir / "r.html").string(), dir, 120);
    ASSERT_EQ(streamed.exit_code, 0) << streamed.err;
    ASSERT_EQ(whole.exit_code, 0) << whole.err;
    const std::string a = test::slurp((dir / "streamed.vcd").string()), b = test::slurp((dir / "whole.vcd").string());
    EXPECT_GT(a.size(), 10000u);
    EXPECT_TRUE(a == b) << "streamed " << a.size() << " bytes, whole " << b.size() << " bytes";
}

// A board whose only MCU halted says when it halted, not "0 s".
TEST(BoardRun, AHaltedBoardReportsTheTimeItHalted) {
    const auto dir = test::scratch_dir("halted-board");
    const auto r = test::run_command(kWorkflowCli + " run -q --board " + uno() + " " + test::firmware("crash_bad_opcode") + " --for 10ms", dir);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.out.find("simulated  0.000000 s"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("simulated  0.0000"), std::string::npos) << r.out;  // microseconds after reset
}

TEST(GoldenUpdate, RefusesAFailingRunUnlessForced) {
    const auto dir = test::scratch_dir("golden-refuse");
    // blink_timer1 has no serial output and no findings: expecting one fails.
    const fs::path scenario = write(dir / "s.yaml", "board: " + uno() + "\nfirmware: {uno: blink_timer1}\nsteps:\n  - delay: 5ms\n"
                                                    "expect:\n  - findings: 1\ngolden: s.timeline\n");
    const auto r = test::run_command(kWorkflowCli + " golden update " + scenario.string() + kFw, dir);
    EXPECT_EQ(r.exit_code, 1) << r.out;
    EXPECT_NE(r.out.find("expect findings (" + scenario.string() + ":6): 0 findings, expected 1"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("golden: not updated"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir / "s.timeline"));
    const auto forced = test::run_command(kWorkflowCli + " golden update --force " + scenario.string() + kFw, dir);
    EXPECT_EQ(forced.exit_code, 1) << forced.out;  // still a failing run, but written
    EXPECT_TRUE(fs::exists(dir / "s.timeline"));
}

TEST(GoldenUpdate, GoldenIsTheSameWhereverTheCommandRuns) {
    const auto dir = test::scratch_dir("golden-cwd");
    fs::create_directories(dir / "project" / "tests");
    fs::create_directories(dir / "project" / "boards");
    fs::copy_file(uno(), dir / "project" / "boards" / "uno.yaml");
    const fs::path scenario = write(dir / "project" / "tests" / "s.yaml",
                                    "board: ../boards/uno.yaml\nfirmware: {uno: blink_timer1}\nsteps:\n  - delay: 3ms\n"
                                    "golden: s.timeline\n");
    const fs::path golden = dir / "project" / "tests" / "s.timeline";
    auto update_from = [&](const fs::path& cwd, const std::string& scenario_arg) {
        const auto r = test::run_command("cd " + cwd.string() + " && " + kWorkflowCli + " golden update " + scenario_arg + kFw, dir);
        EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
        return test::slurp(golden);
    };
    const std::string from_tests = update_from(dir / "project" / "tests", "s.yaml");
    const std::string from_project = update_from(dir / "project", "tests/s.yaml");
    const std::string from_root = update_from("/", scenario.string());
    EXPECT_EQ(from_tests, from_project);
    EXPECT_EQ(from_tests, from_root);
    EXPECT_NE(from_tests.find("../boards/uno.yaml"), std::string::npos) << from_tests;
}

TEST(Gtkw, SaveFileNamesTheDumpRelativeToItself) {
    const auto dir = test::scratch_dir("gtkw-path");
    fs::create_directories(dir / "traces");
    const auto r = test::run_command("cd " + dir.string() + " && " + kWorkflowCli + " run -q " + test::firmware("blink_timer1") +
                                         " --for 2ms --vcd traces/demo.vcd", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string gtkw = test::slurp(dir / "traces" / "demo.gtkw");
    EXPECT_NE(gtkw.find("[dumpfile] \"demo.vcd\"\n"), std::string::npos) << gtkw;
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// A status while the run goes on (--status-every, --status-file): our card
// print (firmware/boards/sd_print) draws a 20 mm square and its diagonal,
// 6400 steps on each axis (tests/scenarios/ramps_sd_print.yaml); with a
// status every 2 s the first comes after the first slice, the others at 2,
// 4, 6 and 8 s of the 8.2 s job, and the last has both carriages back at
// 100 mm with all 6400 steps made.
TEST(LiveStatus, AStatusLineEveryIntervalAndTheJsonRewritten) {
    const auto dir = test::scratch_dir("live-status");
    std::ofstream(dir / "job.g") << "M23 square.gco\nM24\n";
    const std::string json = (dir / "status.json").string();
    const auto r = test::run_command(kWorkflowCli + " run -q " + test::firmware("sd_print") + " --board " +
                                         test::source_path("tests/scenarios/boards/ramps-sd-square.yaml") + " --gcode " +
                                         (dir / "job.g").string() + " --status-every 2s --status-file " + json, dir, 120);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::vector<std::string> lines;
    std::istringstream err(r.err);
    for (std::string line; std::getline(err, line);) {
        if (line.rfind("status ", 0) == 0) lines.push_back(line);
    }
    ASSERT_EQ(lines.size(), 5u) << r.err;
    EXPECT_EQ(lines[1].rfind("status 2.000 s (wall ", 0), 0u) << lines[1];
    EXPECT_NE(lines[4].find("x 100.000 mm (6400 steps), y 100.000 mm (6400 steps)"), std::string::npos) << lines[4];
    EXPECT_NE(lines[4].find("job 2 of 2 lines answered, findings 0"), std::string::npos) << lines[4];
    const std::string status = test::slurp(json);
    EXPECT_NE(status.find("\"x\": {\"position_mm\": 100.000000, \"steps\": 6400}"), std::string::npos) << status;
    // A JSON reader that is not ours takes it.
    const auto parsed = test::run_command("python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d[\"findings\"], "
                                          "d[\"job\"][\"answered\"])' " + json, dir);
    EXPECT_EQ(parsed.out, "0 2\n") << parsed.err;
}

// kill -USR1 asks a long run for its status at once, without ending it
// (it ends here on SIGINT; the busy loop runs far longer than the test waits).
TEST(LiveStatus, SigusrOneAsksForAStatusNow) {
    const auto dir = test::scratch_dir("live-status-usr1");
    const auto r = test::run_command("(" + kWorkflowCli + " run -q --board " + uno() + " " + test::firmware("busy_poll") +
                                         " --for 100000s & pid=$!; sleep 1; kill -USR1 $pid; sleep 1; kill -INT $pid; wait $pid)",
                                     dir, 60);
    EXPECT_EQ(r.exit_code, 130) << r.err;
    EXPECT_NE(r.err.find("status "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("findings 0"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// The GitHub Action's check step (ci/action/check) with a pattern that
// matches nothing says so, exit 2, before avrbench is run at all.
TEST(ActionCheck, APatternMatchingNoScenarioSaysSo) {
    const auto dir = test::scratch_dir("action-no-match");
    const auto r = test::run_command("AVRBENCH_SCENARIOS='tests/*.yaml' AVRBENCH_RESULTS=results bash " +
                                         test::source_path("ci/action/check"), dir);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, "avrbench action: no scenario files match 'tests/*.yaml'\n");
}

}  // namespace
}  // namespace avrbench
