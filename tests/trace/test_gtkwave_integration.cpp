// gtkwave itself must accept what the writers produce: vcd2fst converts the VCD
// (and fst2vcd gives back the same changes), and the gtkwave viewer, run headless
// under xvfb-run with a Tcl script, loads the VCD through the .gtkw save file and
// shows every signal in its group with the intended format and values.
//
// These tools come from Debian's gtkwave and xvfb packages, installed by
// ci/setup. A missing tool fails the test (it must not skip silently in CI).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "support/Paths.hpp"
#include "trace/GtkwWriter.hpp"
#include "trace/Timeline.hpp"
#include "trace/TraceTestSupport.hpp"
#include "trace/VcdReader.hpp"
#include "trace/VcdWriter.hpp"

namespace avrbench {
namespace {

using trace_test::quoted;
using trace_test::read_text;
using trace_test::ScratchDir;

// The path of `program`, or a test failure telling how to install it.
std::string require_tool(const std::string& program) {
    const std::string path = trace_test::find_program(program);
    if (path.empty())
        ADD_FAILURE() << program << " not found on PATH: run ci/setup (it installs Debian's gtkwave and xvfb)";
    return path;
}

// Two MCUs' worth of signals: 16 MHz and 20 MHz domains, every kind of signal.
Timeline demo_timeline() {
    Timeline timeline;
    const SignalId pb5 = timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, 16000000});
    const SignalId portb = timeline.add_signal({"mcu", "portb", SignalKind::Bus, 8, 16000000});
    const SignalId temp = timeline.add_signal({"heater", "temp_degC", SignalKind::Real, 64, 20000000});
    const SignalId step = timeline.add_signal({"x_driver", "step", SignalKind::Wire, 1, 16000000});
    timeline.record(pb5, 0, 0);
    timeline.record(portb, 0, 0);
    timeline.record_real(temp, 0, 21.5);
    timeline.record(pb5, 16000, 1);       // 1 ms
    timeline.record(portb, 16000, 0x20);  // 1 ms
    timeline.record_real(temp, 40000, 25.25);  // 40000 cycles at 20 MHz = 2 ms
    for (Cycle cycle = 100; cycle < 32000; cycle += 100) timeline.record(step, cycle, (cycle / 100) % 2);
    return timeline;
}

Timeline many_signals() {
    // 9000 > 94 + 94^2: identifiers of one, two and three characters, including
    // '"', '#', '$' and '\' that a careless parser could trip over.
    Timeline timeline;
    for (unsigned i = 0; i < 9000; ++i) {
        const SignalId id = timeline.add_signal(
            {"s" + std::to_string(i / 100), "w" + std::to_string(i), SignalKind::Wire, 1, 16000000});
        timeline.record(id, 0, 0);
        timeline.record(id, 1000 + i, 1);
    }
    return timeline;
}

void expect_same_changes(const VcdDump& original, const VcdDump& converted);

// vcd2fst, then fst2vcd, then compare every variable's changes with the original.
void expect_fst_round_trip(const std::string& vcd2fst, const std::string& fst2vcd, const ScratchDir& dir,
                           const std::string& name) {
    const std::string vcd = dir.file(name + ".vcd");
    const std::string fst = dir.file(name + ".fst");
    const std::string back = dir.file(name + ".back.vcd");
    const std::string log = dir.file(name + ".log");
    ASSERT_EQ(trace_test::run_command(quoted(vcd2fst) + " " + quoted(vcd) + " " + quoted(fst), log), 0)
        << read_text(log);
    ASSERT_TRUE(std::filesystem::exists(fst));
    ASSERT_GT(std::filesystem::file_size(fst), 0u);
    ASSERT_EQ(trace_test::run_command(quoted(fst2vcd) + " " + quoted(fst) + " >" + quoted(back), log), 0)
        << read_text(log);

    expect_same_changes(read_vcd(vcd), read_vcd(back));
}

void expect_same_changes(const VcdDump& original, const VcdDump& converted) {
    EXPECT_EQ(converted.timescale_fs, original.timescale_fs);
    EXPECT_EQ(converted.end_time, original.end_time);
    ASSERT_EQ(converted.variables.size(), original.variables.size());
    for (const VcdVariable& var : original.variables) {
        const VcdVariable* other = converted.find(var.full_name());
        ASSERT_NE(other, nullptr) << var.full_name();
        EXPECT_EQ(other->width, var.width) << var.full_name();
        ASSERT_EQ(other->changes.size(), var.changes.size()) << var.full_name();
        for (std::size_t i = 0; i < var.changes.size(); ++i) {
            EXPECT_EQ(other->changes[i].time, var.changes[i].time) << var.full_name() << " change " << i;
            if (var.type == "real")
                EXPECT_EQ(std::stod(other->changes[i].value), std::stod(var.changes[i].value)) << var.full_name();
            else
                EXPECT_EQ(other->changes[i].value, var.changes[i].value) << var.full_name() << " change " << i;
        }
    }
}

TEST(GtkwaveAcceptsOurFiles, VcdConvertsToFstAndBackUnchanged) {
    const std::string vcd2fst = require_tool("vcd2fst");
    const std::string fst2vcd = require_tool("fst2vcd");
    if (vcd2fst.empty() || fst2vcd.empty()) return;
    ScratchDir dir;
    VcdOptions options;
    options.end_cycle = 48000;  // 3 ms at 16 MHz
    write_vcd(demo_timeline(), dir.file("demo.vcd"), options);
    expect_fst_round_trip(vcd2fst, fst2vcd, dir, "demo");
    write_vcd(many_signals(), dir.file("many.vcd"));
    expect_fst_round_trip(vcd2fst, fst2vcd, dir, "many");
}

// `run --vcd NAME.fst` writes gtkwave's FST (through Debian's vcd2fst) with
// the very changes `--vcd NAME.vcd` writes, a save file naming the .fst, and
// nothing else beside it; without vcd2fst on PATH it stops before the run
// with one line (exit 2).
TEST(GtkwaveAcceptsOurFiles, RunWritesFstWithTheVcdsChanges) {
    const std::string fst2vcd = require_tool("fst2vcd");
    if (fst2vcd.empty()) return;
    ScratchDir dir;
    const std::string run = quoted(::avrbench::test::cli()) + " run -q " +
                            quoted(std::string(::avrbench::test::firmware_dir()) + "/blink_timer1.elf") + " --for 20ms --vcd ";
    ASSERT_EQ(trace_test::run_command(run + quoted(dir.file("b.vcd")), dir.file("vcd.log")), 0) << read_text(dir.file("vcd.log"));
    ASSERT_EQ(trace_test::run_command(run + quoted(dir.file("b.fst")), dir.file("fst.log")), 0) << read_text(dir.file("fst.log"));
    ASSERT_EQ(trace_test::run_command(quoted(fst2vcd) + " " + quoted(dir.file("b.fst")) + " >" + quoted(dir.file("back.vcd")),
                                      dir.file("back.log")),
              0);
    const VcdDump vcd = read_vcd(dir.file("b.vcd"));
    const VcdDump back = read_vcd(dir.file("back.vcd"));
    // blink_timer1 toggles PB5 every 16000 cycles from 16051: 19 times in 20 ms, plus its initial value.
    ASSERT_NE(vcd.find("mcu.PB5"), nullptr);
    EXPECT_EQ(vcd.find("mcu.PB5")->changes.size(), 20u);
    expect_same_changes(vcd, back);
    EXPECT_NE(read_text(dir.file("b.gtkw")).find("[dumpfile] \"b.fst\""), std::string::npos) << read_text(dir.file("b.gtkw"));
    std::vector<std::string> left;
    for (const auto& e : std::filesystem::directory_iterator(dir.file(""))) left.push_back(e.path().filename().string());
    std::sort(left.begin(), left.end());
    EXPECT_EQ(left, (std::vector<std::string>{"b.fst", "b.gtkw", "b.vcd", "back.log", "back.vcd", "fst.log", "vcd.log"}));

    const int code = trace_test::run_command("PATH=/nonexistent " + run + quoted(dir.file("c.fst")), dir.file("nofst.log"));
    EXPECT_EQ(code, 2);
    const std::string err = read_text(dir.file("nofst.log"));
    EXPECT_NE(err.find("writing FST needs vcd2fst (Debian's gtkwave package)"), std::string::npos) << err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("c.fst")));
}

// Runs gtkwave headless on `gtkw` (which names its dump) with a Tcl script that
// prints "KEY value" lines; returns them. xvfb-run -a can lose a race for a
// display number with another X server starting, so a failed start is retried.
std::map<std::string, std::string> run_gtkwave(const ScratchDir& dir, const std::string& gtkw,
                                                const std::string& tcl_body, const std::string& cwd = "/") {
    const std::string xvfb_run = require_tool("xvfb-run");
    const std::string gtkwave = require_tool("gtkwave");
    if (xvfb_run.empty() || gtkwave.empty()) return {};
    const std::string script = dir.file("check.tcl");
    // catch: a Tcl error must still reach /File/Quit, or gtkwave would wait forever.
    trace_test::write_text(script, "if {[catch {\n" + tcl_body +
                                       "} err]} { puts \"TCLERROR $err\" }\n"
                                       "puts \"DONE 1\"\n"
                                       "gtkwave::/File/Quit\n");
    const std::string log = dir.file("gtkwave.log");
    // Run from another directory: the save file's relative [dumpfile] must still resolve.
    const std::string command = "cd " + quoted(cwd) + " && timeout 120 " + quoted(xvfb_run) + " -a " + quoted(gtkwave) +
                                " --script=" + quoted(script) + " " + quoted(gtkw);
    std::string output;
    for (int attempt = 0; attempt < 3; ++attempt) {
        trace_test::run_command(command, log);
        output = read_text(log);
        if (output.find("DONE 1") != std::string::npos) break;
    }
    std::map<std::string, std::string> values;
    std::istringstream lines(output);
    std::string line;
    while (std::getline(lines, line)) {
        const auto space = line.find(' ');
        if (space != std::string::npos) values.emplace(line.substr(0, space), line.substr(space + 1));
    }
    EXPECT_EQ(values.count("DONE"), 1u) << "gtkwave did not run the script:\n" << output;
    EXPECT_EQ(values.count("TCLERROR"), 0u) << output;
    return values;
}

TEST(GtkwaveAcceptsOurFiles, ViewerLoadsDumpThroughSaveFile) {
    ScratchDir dir;
    const Timeline timeline = demo_timeline();
    VcdOptions options;
    options.end_cycle = 48000;  // 3 ms at 16 MHz
    write_vcd(timeline, dir.file("demo.vcd"), options);
    write_gtkw(timeline, dir.file("demo.gtkw"), "demo.vcd");  // relative to the save file

    // gtkwave shows a 100ps dump in ps: 1 ms = 10^9.
    const std::string tcl =
        "puts \"FACS [gtkwave::getNumFacs]\"\n"
        "puts \"MAXTIME [gtkwave::getMaxTime]\"\n"
        "puts \"DIM [gtkwave::getTimeDimension]\"\n"
        "set n [gtkwave::getTotalNumTraces]\n"
        "puts \"TRACES $n\"\n"
        "for {set i 0} {$i < $n} {incr i} {\n"
        "  puts \"TRACE$i [gtkwave::getTraceNameFromIndex $i]/[format %x [gtkwave::getTraceFlagsFromIndex $i]]\"\n"
        "}\n"
        "gtkwave::setMarker 1500000000\n"
        "puts \"AT1.5ms [gtkwave::getTraceValueAtMarkerFromName mcu.PB5]/"
        "[gtkwave::getTraceValueAtMarkerFromName {mcu.portb[7:0]}]/"
        "[gtkwave::getTraceValueAtMarkerFromName heater.temp_degC]\"\n"
        "gtkwave::setMarker 2500000000\n"
        "puts \"AT2.5ms [gtkwave::getTraceValueAtMarkerFromName heater.temp_degC]\"\n";
    auto values = run_gtkwave(dir, dir.file("demo.gtkw"), tcl);
    if (values.empty()) return;

    EXPECT_EQ(values["FACS"], "11");  // PB5, portb as 8 one-bit wires (joined again by the .gtkw), temp_degC, step
    EXPECT_EQ(values["DIM"], "p");
    EXPECT_EQ(values["MAXTIME"], "3000000000");  // end_cycle: 3 ms
    // 4 signals + a begin and an end marker per scope (3) + 3 analog height rows.
    ASSERT_EQ(values["TRACES"], "13");
    const std::vector<std::string> expected_traces = {
        "mcu/800200",    "PB5/28",          "portb[7:0]/22", "mcu/1000200", "heater/800200",
        "temp_degC/8028", "/20000",          "/20000",        "/20000",      "heater/1000200",
        "x_driver/800200", "step/28",        "x_driver/1000200"};
    for (std::size_t i = 0; i < expected_traces.size(); ++i)
        EXPECT_EQ(values["TRACE" + std::to_string(i)], expected_traces[i]) << "trace " << i;
    // At 1.5 ms: PB5 rose at 1 ms, portb = 0x20 shown in hex, temp still 21.5 (changes at 2 ms).
    EXPECT_EQ(values["AT1.5ms"], "1/20/21.5");
    EXPECT_EQ(values["AT2.5ms"], "25.25");
}

TEST(GtkwaveAcceptsOurFiles, ViewerLoadsNineThousandSignals) {
    ScratchDir dir;
    const Timeline timeline = many_signals();
    write_vcd(timeline, dir.file("many.vcd"));
    write_gtkw(timeline, dir.file("many.gtkw"), "many.vcd");
    // Signal 8999 (identifier of 3 characters) rises at cycle 9999 = 624,937,500 ps;
    // signal 100 (2 characters) at cycle 1100 = 68,750,000 ps.
    const std::string tcl =
        "puts \"FACS [gtkwave::getNumFacs]\"\n"
        "puts \"TRACES [gtkwave::getTotalNumTraces]\"\n"
        "gtkwave::setMarker 624937499\n"
        "puts \"BEFORE [gtkwave::getTraceValueAtMarkerFromName s89.w8999]\"\n"
        "gtkwave::setMarker 624937500\n"
        "puts \"AT [gtkwave::getTraceValueAtMarkerFromName s89.w8999]/"
        "[gtkwave::getTraceValueAtMarkerFromName s1.w100]/[gtkwave::getTraceValueAtMarkerFromName s0.w3]\"\n";
    auto values = run_gtkwave(dir, dir.file("many.gtkw"), tcl);
    if (values.empty()) return;
    EXPECT_EQ(values["FACS"], "9000");
    EXPECT_EQ(values["TRACES"], "9180");  // 9000 signals + 2 group markers x 90 scopes
    EXPECT_EQ(values["BEFORE"], "0");
    EXPECT_EQ(values["AT"], "1/1/1");
}

// A board run through the CLI, opened the way a user would: from the traces
// folder (`cd traces && gtkwave u.gtkw`) and from elsewhere. Labels appear
// under their board-file names, the UART as text.
TEST(GtkwaveAcceptsOurFiles, CliRunOpensFromAnyFolderWithLabelsAndUartText) {
    ScratchDir dir;
    std::filesystem::create_directories(dir.file("traces"));
    trace_test::write_text(dir.file("in.txt"), "hi\n");
    trace_test::run_command("cd " + quoted(dir.file("")) + " && " + quoted(::avrbench::test::cli()) + " run -q --board " +
                                quoted(std::string(::avrbench::test::source_dir()) + "/bench/boards/arduino-uno.yaml") + " " +
                                quoted(std::string(::avrbench::test::firmware_dir()) + "/uart_echo.elf") +
                                " --for 5ms --uart-in in.txt --vcd traces/u.vcd",
                            dir.file("run.log"));
    // uart_echo's banner "avrbench uart_echo\r\n" goes out one frame per
    // 1360 cycles = 85 us from the first at 27500 x 100 ps = 2.75 us:
    // at 1 ms the 12th frame (index 11) is on the line, 'r' of "uart_echo"
    // (2.75 us + 11 * 85 us = 937.75 us <= 1 ms < 1022.75 us).
    const std::string tcl =
        "set n [gtkwave::getTotalNumTraces]\n"
        "for {set i 0} {$i < $n} {incr i} {\n"
        "  puts \"TRACE$i [gtkwave::getTraceNameFromIndex $i]/[format %x [gtkwave::getTraceFlagsFromIndex $i]]\"\n"
        "}\n"
        "gtkwave::setMarker 1000000000\n"
        "puts \"AT1ms [gtkwave::getTraceValueAtMarkerFromName {uno.uart0_tx[7:0]}]/"
        "[gtkwave::getTraceValueAtMarkerFromName labels.led]\"\n";
    for (const std::string& cwd : {dir.file("traces"), std::string("/")}) {
        const std::string gtkw = cwd == "/" ? dir.file("traces/u.gtkw") : "u.gtkw";
        auto values = run_gtkwave(dir, gtkw, tcl, cwd);
        if (values.empty()) return;
        // Looked up by name: the order of signals in a group is the
        // recorder's, not part of what this test pins.
        auto flags_of = [&values](const std::string& name) {
            for (const auto& [key, value] : values)
                if (key.rfind("TRACE", 0) == 0 && value.rfind(name + "/", 0) == 0) return value.substr(name.size() + 1);
            return std::string("(no trace named ") + name + ")";
        };
        EXPECT_EQ(flags_of("uart0_tx[7:0]"), "820") << cwd;  // 0x800 ASCII | 0x20 right-justified
        EXPECT_EQ(flags_of("led"), "28") << cwd;             // the D13 LED label of the board file
        // What gtkwave shows first is the board file's names (its nets -
        // the serial host's rx and tx - then its labels); the MCU's raw
        // pins come last, in a collapsed group (TR_CLOSED 0x400000 | group begin).
        EXPECT_EQ(values["TRACE0"], "nets/800200") << cwd;
        EXPECT_EQ(values["TRACE1"], "host_rx/28") << cwd;
        bool labels_group = false, pins_collapsed = false;
        for (const auto& [key, value] : values) {
            labels_group = labels_group || value == "labels/800200";
            pins_collapsed = pins_collapsed || value == "uno pins/c00200";
        }
        EXPECT_TRUE(labels_group) << cwd;
        EXPECT_TRUE(pins_collapsed) << cwd;
        EXPECT_EQ(values["AT1ms"], "r/0") << cwd;
    }
}

// The save file opens zoomed to the whole run (docs/CLI.md), as gtkwave
// itself reports its window: from 0 to at least the dump's end, and not
// zoomed out past a sixth more (a 310 ms run once opened at 0-287 ms).
TEST(GtkwaveAcceptsOurFiles, TheSaveFileOpensOnTheWholeRun) {
    ScratchDir dir;
    for (const char* length : {"310ms", "3s"}) {
        trace_test::run_command(quoted(::avrbench::test::cli()) + " run -q " +
                                    quoted(std::string(::avrbench::test::firmware_dir()) + "/blink_timer1.elf") + " --for " +
                                    length + " --vcd " + quoted(dir.file("b.vcd")),
                                dir.file("run.log"));
        const std::string tcl =
            "puts \"START [gtkwave::getWindowStartTime]\"\n"
            "puts \"END [gtkwave::getWindowEndTime]\"\n"
            "puts \"MAX [gtkwave::getMaxTime]\"\n";
        auto values = run_gtkwave(dir, dir.file("b.gtkw"), tcl);
        if (values.empty()) return;
        const double end = std::stod(values["END"]), max = std::stod(values["MAX"]);
        EXPECT_EQ(values["START"], "0") << length;
        EXPECT_GE(end, max) << length;
        EXPECT_LE(end, max * 7 / 6) << length;
    }
}

}  // namespace
}  // namespace avrbench
