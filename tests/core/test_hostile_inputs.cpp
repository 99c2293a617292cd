// Issue 32's classes of hostile input, one test each at the library level
// (the CLI-level sample of a few hundred inputs is the ctest hostile.inputs,
// tests/hostile/hostile.py): YAML alias cycles and expansion bombs, files
// that are not regular files or are too large, outputs that name each other
// or an input, --pty-link over a file, a host flooding the pty, golden lines
// that cannot be read whole and golden repeats longer than the run, boards
// of too many MCUs, heaters no bench holds, and --pty's receive queue.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "boards/BoardFile.hpp"
#include "boards/YamlKeys.hpp"
#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "core/OutputFile.hpp"
#include "stimulus/PtyBridge.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"
#include "trace/TimelineText.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

namespace fs = std::filesystem;

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const BadInput& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(HostileYaml, AnAliasThatContainsItselfIsAnErrorAtItsLine) {
    EXPECT_EQ(error_of([] { load_yaml("a: 1\nb: &x [*x]\n", "f.yaml"); }),
              "f.yaml:2: a YAML alias refers to a node that contains it (a cycle)");
    EXPECT_EQ(error_of([] { load_yaml("m: &x {a: 1, b: *x}\n", "f.yaml"); }),
              "f.yaml:1: a YAML alias refers to a node that contains it (a cycle)");
}

TEST(HostileYaml, AliasesThatExpandPastTheBudgetAreAnError) {
    // 10 aliases of 10, 7 levels deep: 10^7 nodes from 7 lines.
    std::string text = "l0: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
    for (int i = 1; i < 7; ++i) {
        text += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [";
        for (int k = 0; k < 10; ++k) text += (k ? ", *l" : "*l") + std::to_string(i - 1);
        text += "]\n";
    }
    const auto started = std::chrono::steady_clock::now();
    EXPECT_NE(error_of([&] { load_yaml(text, "bomb.yaml"); }).find("expands to more than 1000000 nodes"), std::string::npos);
    // A guard, not a measure: stopping at 10^6 nodes takes well under a second.
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(30));
}

TEST(HostileYaml, PlainAliasesStillWork) {
    const auto board = parse_board_text(
        "board: aliased\nmcus:\n  a: &mcu {type: atmega328p, clock: 16MHz}\n  b: *mcu\n", "aliased.yaml");
    ASSERT_EQ(board.mcus.size(), 2u);
    EXPECT_EQ(board.mcus[1].clock_hz, 16'000'000u);
    EXPECT_EQ(board.mcus[1].type, "atmega328p");
}

TEST(HostileYaml, ASerialPortGivenAsAListIsABoardErrorNotAnInternalOne) {
    EXPECT_EQ(error_of([] {
                  parse_board_text("mcus:\n  uno: {type: atmega328p, clock: 16MHz}\nserial:\n  host: [uno, 0]\n", "b.yaml");
              }),
              "b.yaml:4: serial port 'host' must be a map {mcu, usart, flow, ...}");
}

TEST(HostileFiles, AFifoADeviceAndAFolderAreRefusedWithoutBlocking) {
    const auto dir = test::scratch_dir("hostile-files");
    const std::string fifo = (dir / "fifo").string();
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    // Nobody writes to the FIFO: opening it for reading would block forever.
    EXPECT_EQ(error_of([&] { read_input_file(fifo, "golden timeline", 1024); }),
              "golden timeline: " + fifo + ": is a FIFO, not a regular file");
    EXPECT_EQ(error_of([] { read_input_file("/dev/zero", "--uart-in", 1024); }),
              "--uart-in: /dev/zero: is a character device, not a regular file");
    EXPECT_EQ(error_of([&] { read_input_file(dir.string(), "board file", 1024); }),
              "board file: " + dir.string() + ": is a folder, not a regular file");
}

TEST(HostileFiles, AFileOverItsCapIsRefusedBeforeItIsRead) {
    const auto dir = test::scratch_dir("hostile-sparse");
    const std::string huge = (dir / "huge").string();
    {
        std::ofstream(huge) << "x";
    }
    fs::resize_file(huge, std::uintmax_t{2} << 30);  // 2 GiB, sparse: nothing of it is ever read
    EXPECT_EQ(error_of([&] { read_input_file(huge, "G-code file", kMaxGcodeFileBytes); }),
              "G-code file: " + huge + ": 2048.0 MiB is more than a G-code file may be (64.0 MiB; docs/CLI.md, \"Limits\")");
}

TEST(HostileFiles, NamesInMessagesAreEscapedToOneLine) {
    EXPECT_EQ(escaped("a\nb\x1b[31m\xc3"), "a\\nb\\x1b[31m\\xc3");
    EXPECT_EQ(quoted_text("it's"), "'it\\'s'");
    EXPECT_EQ(error_of([] { read_input_file("/nonexistent/a\nb", "--gcode", 10); }),
              "--gcode: /nonexistent/a\\nb: no such file");
}

TEST(HostileOutputs, TwoOutputsOnOneFileOrAnOutputOnAnInputAreRefused) {
    const auto dir = test::scratch_dir("hostile-outputs");
    const std::string input = (dir / "drawing.dxf").string(), link = (dir / "link").string();
    std::ofstream(input) << "0\nEOF\n";
    ASSERT_EQ(::link(input.c_str(), link.c_str()), 0);
    {
        RunFiles files;
        files.input(input, "the drawing");
        files.output(input, "-o");
        EXPECT_EQ(error_of([&] { files.check(); }),
                  "-o: " + input + " is also read as the drawing; give each output a file of its own");
    }
    {
        RunFiles files;  // a hard link is the same file
        files.input(input, "the drawing");
        files.output(link, "--nc");
        EXPECT_NE(error_of([&] { files.check(); }).find("--nc: " + link + " is also read as the drawing (" + input + ")"),
                  std::string::npos);
    }
    {
        RunFiles files;  // neither exists yet: the same normalized path
        fs::create_directory(dir / "sub");
        files.output((dir / "x.vcd").string(), "--vcd");
        files.output((dir / "sub" / ".." / "x.vcd").string(), "--uart-out");
        EXPECT_NE(error_of([&] { files.check(); }).find("is also written as --vcd"), std::string::npos);
    }
    {
        RunFiles files;
        files.input(input, "the drawing");
        files.output((dir / "out.nc").string(), "-o");
        files.output((dir / "out.vcd").string(), "--vcd");
        EXPECT_EQ(error_of([&] { files.check(); }), "(no error)");
    }
}

TEST(HostilePty, ALinkOverAFileIsRefusedAndTheFileKept) {
    const auto dir = test::scratch_dir("hostile-pty-link");
    const std::string victim = (dir / "victim.txt").string();
    std::ofstream(victim) << "keep";
    Bench bench(test::source_path("bench/boards/arduino-uno.yaml"), test::firmware("uart_echo"));
    EXPECT_NE(error_of([&] { PtyBridge pty(bench.serial("host"), victim); }).find("exists and is not a link to a pseudo-terminal"),
              std::string::npos);
    std::ifstream in(victim);
    std::string kept;
    in >> kept;
    EXPECT_EQ(kept, "keep");
}

TEST(HostilePty, AHostFloodingThePtyIsThrottledNotQueued) {
    Bench bench(test::source_path("bench/boards/arduino-uno.yaml"), test::firmware("uart_echo"));
    PtyBridge pty(bench.serial("host"));
    const int host = ::open(pty.path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(host, 0);
    // The host writes until the pty refuses more (EAGAIN): the kernel's
    // buffer is full because the bench stopped reading at its 4 KiB queue.
    const std::string chunk(4096, 'G');
    std::size_t written = 0;
    for (int i = 0; i < 4096; ++i) {
        pty.pump();
        const ssize_t n = ::write(host, chunk.data(), chunk.size());
        if (n <= 0) break;
        written += static_cast<std::size_t>(n);
    }
    EXPECT_LT(written, std::size_t{1} << 20) << "the host could write without bound";
    EXPECT_LE(bench.serial("host").pending_rx(), 4096u);
    ::close(host);
}

TEST(HostileGolden, ALineWithMoreThanItsItemsIsRefusedWithItsLine) {
    const std::string head = "avrbench-timeline 1\nsignal uno.PB5 wire 1 16000000\n@uno.PB5\n0 0\n";
    EXPECT_EQ(error_of([&] { parse_timeline_text(head + "+17 0 +15 1\n", "g.timeline"); }),
              "g.timeline:5: '+15' after a change (one item per line)");
    EXPECT_EQ(error_of([&] { parse_timeline_text(head + "*3 +5 1 +5\n", "g.timeline"); }),
              "g.timeline:5: repeat block: '+5' has no value");
}

TEST(HostileGolden, ARepeatIsReadNoFurtherThanTheRunItIsComparedWith) {
    const std::string text =
        "avrbench-timeline 1\nend 16000000000000 16000000\nsignal uno.PB5 wire 1 16000000\n@uno.PB5\n0 0\n*24999990 +1 1 +1 0\n";
    const auto started = std::chrono::steady_clock::now();
    // A run of 1 ms: 16000 cycles at 16 MHz; one event past it is kept.
    const ParsedTimeline parsed = parse_timeline_text(text, "g.timeline", 1e-3);
    EXPECT_EQ(parsed.timeline.events().size(), 1u + 16000u + 1u);
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(30));  // a guard: it takes milliseconds
    // Without a run to bound it, the file's own end does: an event after it is malformed.
    EXPECT_NE(error_of([] {
                  parse_timeline_text("avrbench-timeline 1\nend 100 16000000\nsignal uno.PB5 wire 1 16000000\n@uno.PB5\n0 0\n+101 1\n",
                                      "g.timeline");
              }).find("g.timeline:6: cycle 101 is after the timeline's end"),
              std::string::npos);
}

TEST(HostileBoards, MoreThanSixteenMcusIsABoardError) {
    std::string text = "board: many\nmcus:\n";
    for (int i = 0; i < 17; ++i) text += "  m" + std::to_string(i) + ": {type: atmega328p, clock: 16MHz}\n";
    EXPECT_EQ(error_of([&] { parse_board_text(text, "many.yaml"); }),
              "many.yaml:3: 17 MCUs; a board holds at most 16 (their lockstep costs grow with the square of the count)");
}

TEST(HostileBoards, AHeaterNoBenchHoldsIsABoardError) {
    // 1000 V across 1 ohm is 1 MW; into a 1 J/K block, 10^6 K/s.
    const std::string board =
        "board: absurd\nmcus:\n  uno: {type: atmega328p, clock: 16MHz}\nparts:\n"
        "  plant: {type: thermal_plant, preset: custom, heat_capacity: 1J/K, ambient_conductance: 0.1W/K, "
        "sensor_time_constant: 1s}\n"
        "  heat: {type: heater, preset: custom, resistance: 1ohm, supply: 1000V}\n"
        "nets:\n  body: [heat.body, plant.body]\n  gate: [uno.PD6, heat.gate]\n";
    const auto dir = test::scratch_dir("hostile-heater");
    std::ofstream(dir / "b.yaml") << board;
    EXPECT_NE(error_of([&] { Bench bench((dir / "b.yaml").string(), test::firmware("blink_timer1")); })
                  .find("1e+06 W into the block node of plant 'plant' (1 J/K) heats it at 1e+06 K/s, more than 1000 K/s"),
              std::string::npos);
}

}  // namespace
}  // namespace avrbench
