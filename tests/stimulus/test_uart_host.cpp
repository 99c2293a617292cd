// The G-code host (bench/stimulus/UartHost) against real firmware in simavr:
// stepdir_test (firmware/boards/stepdir_test, its README lists the commands
// and answers), uart_echo and sleep_idle. Job files are in tests/stimulus/gcode.
//
// Numbers used below (ATmega328P at 16 MHz):
//   1 s = 16,000,000 cycles, so the default 2 s timeout = 32,000,000 cycles;
//   USART0 at UBRR0 = 16, U2X0 = 1: 8 * 17 = 136 cycles/bit, 10-bit 8N1 frame
//   = 1360 cycles = 85 us per byte (datasheet §19.3.1, §19.4).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "mcu/ElfImage.hpp"
#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "stimulus/UartHost.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

constexpr Cycle kCyclesPerSecond = 16'000'000;
// The scheduler runs a callback at the first instruction boundary at or
// after its cycle (an instruction takes at most 5 cycles), or one cycle past
// it when the core sleeps (Scheduler tests).
constexpr Cycle kBoundarySlack = 5;

std::string job(const std::string& name) { return test::source_path("tests/stimulus/gcode/" + name); }

UartHostOptions banner_first(FlowControl flow = FlowControl::SendAndWait) {
    UartHostOptions o;
    o.flow = flow;
    o.startup = Startup::WaitForBanner;  // stepdir_test prints "stepdir_test ready" first
    return o;
}

struct StepDirHost {
    Mcu mcu{ElfImage::load(test::firmware("stepdir_test"))};
    UartHost host;
    explicit StepDirHost(UartHostOptions options = banner_first()) : host(mcu, 0, std::move(options)) {}
};

std::vector<TranscriptEntry> of_direction(const std::vector<TranscriptEntry>& t, Direction d) {
    std::vector<TranscriptEntry> out;
    for (const auto& e : t) {
        if (e.direction == d) out.push_back(e);
    }
    return out;
}

// --- parsing (no MCU) ----------------------------------------------------------

TEST(UartHostParse, StripsCommentsAndBlankLinesAndKeepsTheRestAsWritten) {
    const auto lines = parse_gcode(
        "; header\n"
        "\n"
        "G1 X10 ; move\n"
        "G1 (inline) Y5\r\n"
        "   \t\n"
        "(only a comment)\n"
        "M3 S1000   \n"
        "G0 X1 (unclosed\n",
        "job.gcode");
    ASSERT_EQ(lines.size(), 4u);
    EXPECT_EQ(lines[0].text, "G1 X10");
    EXPECT_EQ(lines[0].number, 3u);  // the third line of the text
    EXPECT_EQ(lines[1].text, "G1  Y5");  // the comment goes, the spaces around it stay
    EXPECT_EQ(lines[1].number, 4u);
    EXPECT_EQ(lines[2].text, "M3 S1000   ");  // sent as written: trailing blanks are bytes a buffer test counts
    EXPECT_EQ(lines[2].number, 7u);
    EXPECT_EQ(lines[3].text, "G0 X1");  // an unclosed '(' runs to the end of the line, the blank before it goes
    EXPECT_EQ(lines[3].number, 8u);
    EXPECT_EQ(lines[3].origin, "job.gcode");
}

TEST(UartHostParse, FlowControlNamesAreTheBoardFilesSpelling) {
    EXPECT_EQ(parse_flow_control("send_and_wait", "x"), FlowControl::SendAndWait);
    EXPECT_EQ(parse_flow_control("character_counting", "x"), FlowControl::CharacterCounting);
    EXPECT_THROW(parse_flow_control("xon_xoff", "board.yaml:3"), BadInput);
}

TEST(UartHost, AddedLinesAreNumberedOnAcrossCalls) {
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    UartHostOptions o;
    o.startup = Startup::WaitForBanner;  // sleep_idle prints nothing: nothing is sent
    UartHost host(mcu, 0, o);
    host.add_lines("G0 X1\n; comment\n");  // lines 1 and 2
    host.add_line("G0 X2");                 // line 3
    host.add_lines("\nG0 X3");              // lines 4 (blank) and 5
    ASSERT_EQ(host.lines().size(), 3u);
    EXPECT_EQ(host.lines()[0].number, 1u);
    EXPECT_EQ(host.lines()[1].number, 3u);
    EXPECT_EQ(host.lines()[2].number, 5u);
    EXPECT_EQ(host.lines()[2].origin, "<lines>");
    EXPECT_EQ(host.lines_sent(), 0u);
    EXPECT_FALSE(host.done());  // not ready: the banner has not come
}

TEST(UartHost, MissingJobFileIsBadInputNamingIt) {
    StepDirHost b;
    try {
        b.host.load_file("/nonexistent/job.gcode");
        FAIL() << "no exception";
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "G-code file: /nonexistent/job.gcode: no such file");
    }
}

// --- a job that goes through ------------------------------------------------------

TEST(UartHost, JobEndsDoneWithOneOkPerLineInOrder) {
    StepDirHost b;
    b.host.load_file(job("short_job.gcode"));
    // short_job.gcode has 13 lines; 4 are comments or blank: 9 commands.
    ASSERT_EQ(b.host.lines().size(), 9u);
    ASSERT_TRUE(b.host.run_until_finished(1.0)) << b.host.tail(10);
    EXPECT_TRUE(b.host.done()) << b.host.failure_message();
    EXPECT_FALSE(b.host.failed());
    EXPECT_EQ(b.host.oks(), 9u);  // stepdir_test answers each command with one ok
    EXPECT_EQ(b.host.errors(), 0u);
    EXPECT_EQ(b.host.lines_acknowledged(), 9u);
    EXPECT_TRUE(b.host.events().empty());

    // Sent lines in job order, with their line numbers in the file.
    const auto sent = of_direction(b.host.transcript(), Direction::Sent);
    const std::vector<std::pair<std::string, std::size_t>> expected = {
        {"E1", 4}, {"W5", 5}, {"L45", 6}, {"X10", 8}, {"X-10", 9}, {"Y20", 10}, {"Z-5", 11}, {"?", 12}, {"E0", 13}};
    ASSERT_EQ(sent.size(), expected.size());
    for (std::size_t i = 0; i < sent.size(); ++i) {
        EXPECT_EQ(sent[i].text, expected[i].first);
        EXPECT_EQ(sent[i].source_line, expected[i].second);
    }
    // Received: banner, 7 oks, the position report and its ok, the last ok.
    // Position after X10, X-10, Y20, Z-5: X 0, Y 20, Z -5.
    const auto received = of_direction(b.host.transcript(), Direction::Received);
    const std::vector<std::string> answers = {"stepdir_test ready", "ok", "ok", "ok", "ok", "ok", "ok", "ok",
                                              "X:0 Y:20 Z:-5", "ok", "ok"};
    ASSERT_EQ(received.size(), answers.size());
    for (std::size_t i = 0; i < received.size(); ++i) EXPECT_EQ(received[i].text, answers[i]) << i;

    // Send and wait: each line after the previous answer, each answer after
    // its line; time never runs backwards in the transcript.
    const auto& t = b.host.transcript();
    for (std::size_t i = 1; i < t.size(); ++i) EXPECT_GE(t[i].cycle, t[i - 1].cycle) << i;
    for (std::size_t i = 1; i < sent.size(); ++i) EXPECT_GT(sent[i].cycle, sent[i - 1].cycle) << i;
    // The 9 lines alternate with their answers: > E1 < ok > W5 < ok ...
    std::size_t index = 1;  // after the banner
    for (std::size_t i = 0; i < 9; ++i) {
        ASSERT_LT(index + 1, t.size());
        EXPECT_EQ(t[index].direction, Direction::Sent);
        EXPECT_EQ(t[index + 1].direction, Direction::Received);
        index += (t[index].text == "?") ? 3 : 2;  // '?' has the report line before its ok
    }
}

TEST(UartHost, WaitsForTheBannerBeforeSending) {
    StepDirHost b;
    b.host.add_line("E1");
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    ASSERT_TRUE(b.host.banner().has_value());
    // "stepdir_test ready\r\n": the \r\n is a line end, not text.
    EXPECT_EQ(*b.host.banner(), "stepdir_test ready");
    const auto& t = b.host.transcript();
    ASSERT_GE(t.size(), 2u);
    EXPECT_EQ(t[0].direction, Direction::Received);
    EXPECT_EQ(t[1].direction, Direction::Sent);
    EXPECT_GE(t[1].cycle, t[0].cycle);
    // The banner's 20 bytes leave one 1360-cycle frame apart (polled UDRE):
    // its last byte is written no earlier than 19 frames into the run.
    EXPECT_GE(t[0].cycle, 19u * 1360u);
}

TEST(UartHost, MessageLinesGoToTheTranscriptOnly) {
    StepDirHost b;
    b.host.add_lines("Mhello\nE1\n");  // stepdir_test: M<text> prints [MSG:<text>], then ok
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    EXPECT_TRUE(b.host.done());
    EXPECT_EQ(b.host.oks(), 2u);
    EXPECT_TRUE(b.host.events().empty());
    const auto received = of_direction(b.host.transcript(), Direction::Received);
    ASSERT_EQ(received.size(), 4u);  // banner, [MSG:hello], ok, ok
    EXPECT_EQ(received[1].text, "[MSG:hello]");
}

TEST(UartHost, TailShowsTheLastEntriesWithTimeAndDirection) {
    StepDirHost b;
    b.host.load_file(job("short_job.gcode"));
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    const std::string tail = b.host.tail(2);
    // The job ends "> E0", "< ok".
    const auto newline = tail.find('\n');
    ASSERT_NE(newline, std::string::npos);
    EXPECT_NE(tail.substr(0, newline).find(" s > E0"), std::string::npos) << tail;
    EXPECT_NE(tail.substr(newline + 1).find(" s < ok\n"), std::string::npos) << tail;
    EXPECT_EQ(std::count(tail.begin(), tail.end(), '\n'), 2);
}

// --- flow control ------------------------------------------------------------------

TEST(UartHost, SendAndWaitNeverHasTwoLinesOutstanding) {
    StepDirHost b(banner_first(FlowControl::SendAndWait));
    b.host.load_file(job("streaming.gcode"));
    ASSERT_TRUE(b.host.run_until_finished(2.0)) << b.host.tail(10);
    EXPECT_TRUE(b.host.done()) << b.host.failure_message();
    // 1 + 40 + 1 lines (streaming.gcode), one at a time.
    EXPECT_EQ(b.host.oks(), 42u);
    EXPECT_EQ(b.host.max_outstanding_lines(), 1u);
    // The longest line is "X-50\n": 5 bytes.
    EXPECT_EQ(b.host.max_outstanding_bytes(), 5u);
}

TEST(UartHost, CharacterCountingFillsButNeverOverflowsTheBuffer) {
    StepDirHost b(banner_first(FlowControl::CharacterCounting));
    b.host.load_file(job("streaming.gcode"));
    ASSERT_TRUE(b.host.run_until_finished(2.0)) << b.host.tail(10);
    EXPECT_TRUE(b.host.done()) << b.host.failure_message();
    EXPECT_EQ(b.host.oks(), 42u);
    // grbl's RX_BUFFER_SIZE (128) is the host's default limit.
    EXPECT_LE(b.host.max_outstanding_bytes(), 128u);
    // It streams: a line of 2.5 ms work (50 steps * 50 us) takes 4-5 bytes
    // = 0.34-0.43 ms on the wire, so the host gets ahead until the next line
    // no longer fits: more than 128 - 5 = 123 bytes outstanding at that point.
    EXPECT_GT(b.host.max_outstanding_bytes(), 123u);
    EXPECT_GT(b.host.max_outstanding_lines(), 20u);  // >= 124 bytes in lines of <= 5 bytes: >= 25 lines
    // And the firmware's own view: its 128-byte ring never overflowed.
    EXPECT_EQ(b.mcu.read_ram_u8("rx_overflow"), 0);
    EXPECT_LE(b.mcu.read_ram_u8("rx_max_fill"), 128);
    EXPECT_GT(b.mcu.read_ram_u8("rx_max_fill"), 60);
    // 40 alternating moves of +-50 steps end where they started.
    const auto received = of_direction(b.host.transcript(), Direction::Received);
    ASSERT_GE(received.size(), 2u);
    EXPECT_EQ(received[received.size() - 2].text, "X:0 Y:0 Z:0");
}

TEST(UartHost, FloodingWithoutFlowControlDoesOverflowTheFirmware) {
    // The control for the test above: rx_overflow can become 1. The same kind
    // of work (X50 = 2.5 ms per 4 bytes) pushed as raw bytes with no flow
    // control: 60 lines = 240 bytes arrive in 240 * 85 us = 20 ms, while the
    // firmware executes only ~8 of them in that time, so more than 128 bytes
    // wait and the ring buffer overflows, as grbl's would.
    StepDirHost b;
    std::string flood;
    for (int i = 0; i < 60; ++i) flood += "X50\n";
    b.host.send_bytes(flood);
    b.mcu.run_for(kCyclesPerSecond / 20);  // 50 ms: all 240 bytes are in
    EXPECT_EQ(b.mcu.read_ram_u8("rx_overflow"), 1);
    EXPECT_EQ(b.mcu.read_ram_u8("rx_max_fill"), 128);
}

TEST(UartHost, CharacterCountingWithASmallerBufferKeepsToIt) {
    UartHostOptions o = banner_first(FlowControl::CharacterCounting);
    o.rx_buffer_bytes = 16;
    StepDirHost b(o);
    b.host.load_file(job("streaming.gcode"));
    ASSERT_TRUE(b.host.run_until_finished(2.0));
    EXPECT_TRUE(b.host.done());
    EXPECT_LE(b.host.max_outstanding_bytes(), 16u);
    EXPECT_GT(b.host.max_outstanding_bytes(), 16u - 5u);  // as above, with 16 instead of 128
}

TEST(UartHost, LineLongerThanTheBufferFailsInsteadOfStalling) {
    UartHostOptions o = banner_first(FlowControl::CharacterCounting);
    o.rx_buffer_bytes = 8;
    StepDirHost b(o);
    b.host.add_lines("E1\nM123456789\n");  // 11 bytes with its '\n' > 8
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    EXPECT_TRUE(b.host.failed());
    ASSERT_EQ(b.host.events().size(), 1u);
    EXPECT_EQ(b.host.events()[0].kind, HostEventKind::LineTooLong);
    EXPECT_EQ(b.host.events()[0].line->number, 2u);
    EXPECT_EQ(b.host.lines_sent(), 1u);
}

// --- a firmware that stops answering ------------------------------------------------

TEST(UartHost, SilentFirmwareTimesOutNamingTheLine) {
    StepDirHost b;  // default line timeout: 2 s
    b.host.load_file(job("no_answer.gcode"));
    ASSERT_TRUE(b.host.run_until_finished(5.0));
    EXPECT_TRUE(b.host.failed());
    EXPECT_FALSE(b.host.done());
    // no_answer.gcode: line 5 is "T   ; the firmware stays silent here".
    EXPECT_EQ(b.host.failure_message(), "line 5 'T' got no answer within 2 s");
    ASSERT_EQ(b.host.events().size(), 1u);
    const HostEvent& e = b.host.events()[0];
    EXPECT_EQ(e.kind, HostEventKind::Timeout);
    ASSERT_TRUE(e.line.has_value());
    EXPECT_EQ(e.line->text, "T");
    EXPECT_EQ(e.line->number, 5u);
    // Simulated time: 2 s = 32,000,000 cycles after T was handed to the port.
    const auto sent = of_direction(b.host.transcript(), Direction::Sent);
    ASSERT_EQ(sent.size(), 3u);  // E1, X5, T; the last X5 is never sent
    EXPECT_EQ(sent[2].text, "T");
    EXPECT_GE(e.cycle, sent[2].cycle + 2 * kCyclesPerSecond);
    EXPECT_LE(e.cycle, sent[2].cycle + 2 * kCyclesPerSecond + kBoundarySlack);
    EXPECT_EQ(b.host.oks(), 2u);
}

TEST(UartHost, DefaultTimeoutIsTwoSimulatedSeconds) {
    // The default with no startup wait, on a firmware that never enables its
    // receiver: the line is never even delivered, let alone answered.
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    UartHost host(mcu, 0);
    host.add_lines("; first line\nG1 X10\n");
    ASSERT_TRUE(host.run_until_finished(5.0));
    EXPECT_EQ(host.failure_message(), "line 2 'G1 X10' got no answer within 2 s");
    ASSERT_EQ(host.events().size(), 1u);
    // Queued at cycle 0 (Startup::Immediately); the clock starts when its 7
    // bytes ("G1 X10\n") would have reached the firmware at the USART's frame
    // length, and runs 2 s = 32,000,000 cycles.
    const Cycle on_the_wire = 7 * mcu.uart(0).cycles_per_frame();
    EXPECT_GE(host.events()[0].cycle, 2 * kCyclesPerSecond + on_the_wire);
    EXPECT_LE(host.events()[0].cycle, 2 * kCyclesPerSecond + on_the_wire + kBoundarySlack);
    EXPECT_EQ(mcu.uart(0).bytes_delivered(), 0u);
}

TEST(UartHost, TimeoutClockRestartsWhenEarlierLinesAreAnswered) {
    // Character counting sends all five lines at once. Q mutes stepdir_test
    // for good, so after the ok for "X800" (800 steps * 50 us = 40 ms of
    // work) Q is the oldest unanswered line, and its 0.5 s run from that ok.
    UartHostOptions o = banner_first(FlowControl::CharacterCounting);
    o.line_timeout_s = 0.5;  // configurable; also names the unit in the message
    StepDirHost b(o);
    b.host.add_lines("E1\nX800\nQ\nX10\nX10\n");
    ASSERT_TRUE(b.host.run_until_finished(2.0));
    EXPECT_EQ(b.host.failure_message(), "line 3 'Q' got no answer within 0.5 s");
    EXPECT_EQ(b.host.lines_sent(), 5u);
    EXPECT_EQ(b.host.oks(), 2u);
    const auto received = of_direction(b.host.transcript(), Direction::Received);
    ASSERT_EQ(received.size(), 3u);  // banner, ok (E1), ok (X800)
    const Cycle last_ok = received[2].cycle;
    EXPECT_GT(last_ok, 800u * 800u);  // X800 alone takes 800 * 800 cycles
    const Cycle timeout_at = b.host.events()[0].cycle;
    EXPECT_GE(timeout_at, last_ok + kCyclesPerSecond / 2);
    EXPECT_LE(timeout_at, last_ok + kCyclesPerSecond / 2 + kBoundarySlack);
}

TEST(UartHost, NoBannerWithinTheTimeoutFails) {
    // sleep_idle never uses its USART.
    Mcu mcu(ElfImage::load(test::firmware("sleep_idle")));
    UartHost host(mcu, 0, banner_first());
    host.add_line("G0 X1");
    EXPECT_TRUE(host.run_until_finished(5.0));
    EXPECT_TRUE(host.failed());
    EXPECT_EQ(host.failure_message(), "no banner from the firmware within 2 s");
    EXPECT_EQ(host.lines_sent(), 0u);
    ASSERT_EQ(host.events().size(), 1u);
    EXPECT_GE(host.events()[0].cycle, 2 * kCyclesPerSecond);
    EXPECT_LE(host.events()[0].cycle, 2 * kCyclesPerSecond + kBoundarySlack);
}

TEST(UartHost, FixedStartupDelayHoldsTheFirstLine) {
    UartHostOptions o;
    o.startup = Startup::FixedDelay;
    o.startup_delay_s = 0.01;  // 160,000 cycles
    StepDirHost b(o);
    b.host.add_line("E1");
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    EXPECT_TRUE(b.host.done());
    const auto sent = of_direction(b.host.transcript(), Direction::Sent);
    ASSERT_EQ(sent.size(), 1u);
    EXPECT_GE(sent[0].cycle, 160'000u);
    EXPECT_LE(sent[0].cycle, 160'000u + kBoundarySlack);
}

// --- answers that are not ok -----------------------------------------------------------

TEST(UartHost, ErrorAnswerIsRecordedWithTheLineThatCausedIt) {
    StepDirHost b;
    b.host.load_file(job("error.gcode"));
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    // grbl-style: error:N answers the line, streaming goes on.
    EXPECT_TRUE(b.host.done());
    EXPECT_EQ(b.host.errors(), 1u);
    EXPECT_EQ(b.host.oks(), 2u);  // E1 and X10
    ASSERT_EQ(b.host.events().size(), 1u);
    const HostEvent& e = b.host.events()[0];
    EXPECT_EQ(e.kind, HostEventKind::Error);
    EXPECT_EQ(e.response, "error:1");  // stepdir_test: error:1 = unknown command letter
    ASSERT_TRUE(e.line.has_value());
    EXPECT_EQ(e.line->text, "G1 X10");
    EXPECT_EQ(e.line->number, 3u);  // error.gcode line 3
    EXPECT_EQ(e.message, "line 3 'G1 X10' got 'error:1'");
    // The event carries the cycle of the answer's last byte.
    const auto received = of_direction(b.host.transcript(), Direction::Received);
    ASSERT_EQ(received.size(), 4u);  // banner, ok, error:1, ok
    EXPECT_EQ(received[2].text, "error:1");
    EXPECT_EQ(e.cycle, received[2].cycle);
}

TEST(UartHost, StopOnErrorStopsAtTheFirstError) {
    UartHostOptions o = banner_first();
    o.stop_on_error = true;
    StepDirHost b(o);
    b.host.load_file(job("error.gcode"));
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    EXPECT_TRUE(b.host.failed());
    EXPECT_EQ(b.host.lines_sent(), 2u);  // E1, G1 X10; X10 is never sent
    EXPECT_EQ(b.host.failure_message(), "line 3 'G1 X10' got 'error:1'");
}

TEST(UartHost, AlarmStopsStreaming) {
    StepDirHost b;
    b.host.add_lines("E1\nA2\nX10\n");  // stepdir_test: A<n> answers "ALARM:<n>" instead of ok
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    EXPECT_TRUE(b.host.failed());
    EXPECT_EQ(b.host.alarms(), 1u);
    EXPECT_EQ(b.host.lines_sent(), 2u);
    ASSERT_EQ(b.host.events().size(), 1u);
    EXPECT_EQ(b.host.events()[0].kind, HostEventKind::Alarm);
    EXPECT_EQ(b.host.events()[0].response, "ALARM:2");
    EXPECT_EQ(b.host.failure_message(), "firmware alarm 'ALARM:2' after line 2 'A2'");
}

TEST(UartHost, FatalStopsStreaming) {
    StepDirHost b;
    b.host.add_lines("E1\nK\nX10\n");  // stepdir_test: K answers "!! killed"
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    EXPECT_TRUE(b.host.failed());
    EXPECT_EQ(b.host.fatals(), 1u);
    EXPECT_EQ(b.host.lines_sent(), 2u);
    EXPECT_EQ(b.host.events()[0].kind, HostEventKind::Fatal);
    EXPECT_EQ(b.host.events()[0].response, "!! killed");
}

// --- what goes on the wire -------------------------------------------------------------

TEST(UartHost, CommentsAndBlankLinesAreNotSent) {
    StepDirHost b;
    b.host.load_file(job("short_job.gcode"));
    ASSERT_TRUE(b.host.run_until_finished(1.0));
    ASSERT_TRUE(b.host.done());
    // Counted by hand from short_job.gcode, '\n' included:
    // E1 3, W5 3, L45 4, X10 4, X-10 5, Y20 4, Z-5 4, ? 2, E0 3 = 32 bytes.
    EXPECT_EQ(b.mcu.uart(0).bytes_delivered(), 32u);
    // The firmware's own count of what it received (stepdir_test globals).
    EXPECT_EQ(b.mcu.read_ram_u16("rx_bytes"), 32u);
    EXPECT_EQ(b.mcu.read_ram_u16("lines_received"), 9u);
    for (const auto& e : of_direction(b.host.transcript(), Direction::Sent)) {
        EXPECT_EQ(e.text.find(';'), std::string::npos) << e.text;
        EXPECT_EQ(e.text.find('('), std::string::npos) << e.text;
        EXPECT_FALSE(e.text.empty());
        EXPECT_NE(e.text.back(), ' ') << e.text;
    }
}

TEST(UartHost, RawBytesGoOutUnchangedAndComeBackUnparsed) {
    // uart_echo echoes every byte after its banner "avrbench uart_echo\r\n".
    Mcu mcu(ElfImage::load(test::firmware("uart_echo")));
    UartHostOptions o;
    o.raw_bytes = true;
    UartHost host(mcu, 0, o);
    const std::string bytes("\x01\xffok\n!!\n", 7);
    host.send_bytes(bytes);
    mcu.run_for(kCyclesPerSecond / 100);  // 10 ms: 27 bytes * 85 us = 2.3 ms
    EXPECT_EQ(host.received_text(), "avrbench uart_echo\r\n" + bytes);
    // No line processing: the echoed "ok" and "!!" are neither acks nor fatal.
    EXPECT_EQ(host.oks(), 0u);
    EXPECT_EQ(host.fatals(), 0u);
    EXPECT_FALSE(host.failed());
    ASSERT_EQ(host.transcript().size(), 1u);
    EXPECT_EQ(host.transcript()[0].text, bytes);
    EXPECT_THROW(host.add_line("G0 X1"), std::logic_error);
}

TEST(UartHost, HostMayGoAwayBeforeTheMcu) {
    Mcu mcu(ElfImage::load(test::firmware("stepdir_test")));
    {
        UartHostOptions o = banner_first();
        o.line_timeout_s = 0.1;
        UartHost host(mcu, 0, o);
        host.add_line("T");  // leaves a timeout pending in the scheduler
        host.run_until_finished(0.01);
        EXPECT_FALSE(host.finished());
    }
    // The Uart's listener and the pending timeout (at 0.1 s) must not touch
    // the dead host (ASan or a crash would show it).
    mcu.uart(0).send("E1\n");  // its ok reaches the Uart's listeners
    mcu.run_for(kCyclesPerSecond / 5);
    EXPECT_FALSE(mcu.halted());
}

}  // namespace
}  // namespace avrbench
