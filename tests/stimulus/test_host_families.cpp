// The UART host against the serial protocols of grbl, Marlin and Teacup as
// their documentation describes them (firmware/host_peer): boot chatter is
// not an answer, keep-alives and long commands do not time out, Marlin's
// Error/Resend/ok triplet resends the line, a welcome mid-job is a restart.
#include <gtest/gtest.h>

#include "mcu/Mcu.hpp"
#include "stimulus/UartHost.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

struct Peer {
    Mcu mcu;
    UartHost host;
    Peer(const std::string& firmware, FirmwareFamily family, FlowControl flow = FlowControl::SendAndWait)
        : mcu(ElfImage::load(test::firmware(firmware))), host(mcu, 0, options(family, flow)) {}
    static UartHostOptions options(FirmwareFamily family, FlowControl flow) {
        UartHostOptions o;
        o.family = family;
        o.flow = flow;
        return o;
    }
    Cycle first_sent() const {
        for (const auto& e : host.transcript()) {
            if (e.direction == Direction::Sent) return e.cycle;
        }
        return 0;
    }
    Cycle received(const std::string& text) const {
        for (const auto& e : host.transcript()) {
            if (e.direction == Direction::Received && e.text == text) return e.cycle;
        }
        return 0;
    }
};

TEST(HostFamilies, GrblBootChatterIsNotAnAnswer) {
    // grbl on a blank EEPROM: error:7 and its settings, the welcome, then
    // ">:error:7" twice. None of it answers line 1.
    Peer p("host_peer_grbl", FirmwareFamily::Grbl, FlowControl::CharacterCounting);
    p.host.add_lines("G21\nG91\nG1 X10 F500\n");
    ASSERT_TRUE(p.host.run_until_finished(5.0)) << p.host.failure_message() << p.host.tail(12);
    EXPECT_TRUE(p.host.done());
    EXPECT_EQ(p.host.lines_acknowledged(), 3u);
    EXPECT_EQ(p.host.oks(), 3u);
    EXPECT_EQ(p.host.errors(), 0u);  // error:7 came before the welcome; >:error:7 is a startup-line report
    EXPECT_TRUE(p.host.events().empty());
    // Nothing was sent before the welcome (grbl would have discarded it).
    EXPECT_GT(p.first_sent(), p.received("Grbl 1.1h ['$' for help]"));
}

TEST(HostFamilies, GrblDwellLongerThanTheLineTimeoutIsNotATimeout) {
    // G4 P3 (grbl: seconds): 3 s of silence, then ok. G4 waits for queued
    // motion first, so it gets the long-command timeout, not the 2 s one.
    UartHostOptions o = Peer::options(FirmwareFamily::Grbl, FlowControl::SendAndWait);
    o.grbl_status_poll_s = 0;  // host_peer answers no '?': test the timeout alone
    Mcu mcu(ElfImage::load(test::firmware("host_peer_grbl")));
    UartHost host(mcu, 0, o);
    host.add_lines("G4 P3\nG1 X1\n");
    ASSERT_TRUE(host.run_until_finished(10.0)) << host.failure_message();
    EXPECT_EQ(host.lines_acknowledged(), 2u);
}

TEST(HostFamilies, GrblRealtimeQueryIsAByteNotALine) {
    // '?' in a job is grbl's realtime status query: sent as one byte, never
    // answered with ok (grbl answers with a '<...>' report).
    Peer p("host_peer_grbl", FirmwareFamily::Grbl);
    p.host.add_lines("G1 X1\n?\nG1 X2\n");
    ASSERT_TRUE(p.host.run_until_finished(5.0)) << p.host.failure_message();
    EXPECT_EQ(p.host.lines_acknowledged(), 3u);
    EXPECT_EQ(p.host.oks(), 2u);
}

TEST(HostFamilies, TimedRealtimeBytesGoOutAtTheirCycleAndHoldTheJobOpen) {
    // grbl's feed hold '!' and resume '~' at chosen times (grbl 1.1
    // "Realtime commands": single bytes outside the streaming protocol).
    Peer p("host_peer_grbl", FirmwareFamily::Grbl, FlowControl::CharacterCounting);
    p.host.add_lines("G1 X1\n");
    const Cycle hold_at = p.mcu.cycles_from_seconds(1.5), resume_at = p.mcu.cycles_from_seconds(2.25);
    p.host.send_bytes_at("!", hold_at);
    p.host.send_bytes_at("~", resume_at);
    // The line is answered within a second; the job is not done before the last byte went.
    ASSERT_TRUE(p.host.run_until_finished(10.0)) << p.host.failure_message();
    EXPECT_GE(p.mcu.cycle(), resume_at);
    std::vector<std::pair<Cycle, std::string>> sent_bytes;
    for (const auto& e : p.host.transcript()) {
        if (e.direction == Direction::Sent && e.source_line == 0) sent_bytes.emplace_back(e.cycle, e.text);
    }
    ASSERT_EQ(sent_bytes.size(), 2u);
    EXPECT_EQ(sent_bytes[0], std::make_pair(hold_at, std::string("!")));
    EXPECT_EQ(sent_bytes[1], std::make_pair(resume_at, std::string("~")));
    EXPECT_EQ(p.host.lines_acknowledged(), 1u);
}

TEST(HostFamilies, TheLineTimeoutStartsOnceTheWholeLineIsSent) {
    // A 3000-byte line at host_peer's 117647 baud (UBRR0 = 16 with U2X0) takes
    // 3001 frames x 10 bits = 255 ms to send; with a 100 ms line timeout the
    // firmware must still be given 100 ms after the newline, not after the
    // first byte (host_peer reads to the newline, then answers ok).
    UartHostOptions o = Peer::options(FirmwareFamily::Grbl, FlowControl::SendAndWait);
    o.grbl_status_poll_s = 0;
    o.line_timeout_s = 0.1;
    Mcu mcu(ElfImage::load(test::firmware("host_peer_grbl")));
    UartHost host(mcu, 0, o);
    host.add_lines("G1 X" + std::string(2996, '1') + "\n");
    ASSERT_TRUE(host.run_until_finished(5.0)) << host.failure_message();
    EXPECT_TRUE(host.done());
    EXPECT_EQ(host.oks(), 1u);
    // The transcript's tail shows such a line by its start and length.
    EXPECT_NE(host.tail(2).find("...' (3000 bytes)"), std::string::npos) << host.tail(2);
}

TEST(HostFamilies, GrblStatusPollsKeepALongMoveAlive) {
    // 5 s of work before the ok (a long move fills grbl's planner) and
    // nothing printed unless asked: the host's '?' every 250 ms brings a
    // report each time, and every report restarts the 2 s line timeout.
    Peer polled("host_peer_grbl", FirmwareFamily::Grbl);
    polled.host.add_lines("BUSY5\n");
    ASSERT_TRUE(polled.host.run_until_finished(10.0)) << polled.host.failure_message();
    EXPECT_EQ(polled.host.lines_acknowledged(), 1u);
    EXPECT_GE(polled.host.status_polls(), 19u);  // 5 s / 0.25 s = 20, give or take the first
    // Without the polls the same firmware is silent for 5 s: a timeout at 2 s.
    UartHostOptions o = Peer::options(FirmwareFamily::Grbl, FlowControl::SendAndWait);
    o.grbl_status_poll_s = 0;
    Mcu mcu(ElfImage::load(test::firmware("host_peer_grbl")));
    UartHost silent(mcu, 0, o);
    silent.add_lines("BUSY5\n");
    silent.run_until_finished(10.0);
    ASSERT_TRUE(silent.failed());
    EXPECT_EQ(silent.events().back().kind, HostEventKind::Timeout);
}

TEST(HostFamilies, GrblWelcomeMidJobIsARestart) {
    Peer p("host_peer_grbl", FirmwareFamily::Grbl);
    p.host.add_lines("G1 X1\nRESET\nG1 X2\n");
    p.host.run_until_finished(5.0);
    ASSERT_TRUE(p.host.failed());
    ASSERT_FALSE(p.host.events().empty());
    EXPECT_EQ(p.host.events().back().kind, HostEventKind::Restarted);
    EXPECT_NE(p.host.failure_message().find("the firmware restarted mid-job (welcome 'Grbl 1.1h"), std::string::npos)
        << p.host.failure_message();
    // After the reset the firmware's boot report "error:7" (blank EEPROM)
    // answered RESET, as it would for any host; line 3 went out and was
    // unanswered when the welcome came again.
    EXPECT_NE(p.host.failure_message().find("line 3 'G1 X2' was unanswered"), std::string::npos) << p.host.failure_message();
}

TEST(HostFamilies, MarlinSlowBootKeepAlivesAndResend) {
    // A 2.1 s SD probe after "start"; M109 with "echo:busy: processing" every
    // second for 5 s; a line with a bad checksum answered Error/Resend/ok and
    // then ok when sent again.
    Peer p("host_peer_marlin", FirmwareFamily::Marlin);
    p.host.add_lines("G28 X\nM109 S200\nG1 X1*99\nG1 X2\n");
    ASSERT_TRUE(p.host.run_until_finished(20.0)) << p.host.failure_message() << p.host.tail(12);
    EXPECT_TRUE(p.host.done());
    EXPECT_EQ(p.host.lines_acknowledged(), 4u);
    EXPECT_EQ(p.host.resends(), 1u);
    // The bad line went out twice; every other line once.
    std::size_t sent_bad = 0;
    for (const auto& e : p.host.transcript()) sent_bad += e.direction == Direction::Sent && e.text == "G1 X1*99" ? 1 : 0;
    EXPECT_EQ(sent_bad, 2u);
    EXPECT_GT(p.first_sent(), p.received("start"));
}

// Marlin answers a G4 when it queues it and, while the dwell runs, says
// "busy: processing" every 2000 ms (HOST_KEEPALIVE_FEATURE,
// DEFAULT_KEEPALIVE_INTERVAL 2): the M105 behind it waits the whole dwell.
// With a 2 s line timeout the first keep-alive would race it; the family's
// default is 2.5 times the interval, 5 s.
TEST(HostFamilies, MarlinKeepAlivesEveryTwoSecondsNeverRaceTheDefaultTimeout) {
    Peer p("host_peer_marlin", FirmwareFamily::Marlin);
    EXPECT_DOUBLE_EQ(p.host.line_timeout_s(), 5.0);
    p.host.add_lines("G4 P60000\nM105\n");
    ASSERT_TRUE(p.host.run_until_finished(80.0)) << p.host.failure_message() << p.host.tail(12);
    EXPECT_EQ(p.host.lines_acknowledged(), 2u);
    EXPECT_TRUE(p.host.events().empty());
}

// A timeout given shorter than that (3 s) still holds, and once a pause
// between outputs has been seen it is never under 2.5 times that pause: 2 s
// between keep-alives (plus the 17 bytes of "busy: processing\r\n" at
// 115200 baud, U2X: 1.36 ms... at most a few ms) makes it 5 s and a bit.
TEST(HostFamilies, TheLineTimeoutFollowsTheKeepAlivesSeen) {
    UartHostOptions o = Peer::options(FirmwareFamily::Marlin, FlowControl::SendAndWait);
    o.line_timeout_s = 3.0;
    Mcu mcu(ElfImage::load(test::firmware("host_peer_marlin")));
    UartHost host(mcu, 0, o);
    EXPECT_DOUBLE_EQ(host.line_timeout_s(), 3.0);
    host.add_lines("G4 P7000\nM105\n");
    ASSERT_TRUE(host.run_until_finished(30.0)) << host.failure_message() << host.tail(12);
    EXPECT_EQ(host.lines_acknowledged(), 2u);
    EXPECT_GE(host.line_timeout_s(), 5.0);
    EXPECT_LT(host.line_timeout_s(), 5.05);
}

// A firmware that halts with a fatal message ends the job at once, naming
// the line: Marlin's kill() and the "fatal:" of a homing failure.
TEST(HostFamilies, FatalMessagesEndTheJobNamingTheLine) {
    for (const char* line : {"FATAL", "KILL"}) {
        Peer p("host_peer_marlin", FirmwareFamily::Marlin);
        p.host.add_lines(std::string("G1 X1\n") + line + "\nG1 X2\n");
        p.host.run_until_finished(20.0);
        ASSERT_TRUE(p.host.failed()) << line;
        ASSERT_EQ(p.host.events().size(), 1u) << line;
        const HostEvent& e = p.host.events().front();
        EXPECT_EQ(e.kind, HostEventKind::Fatal) << line;
        ASSERT_TRUE(e.line.has_value()) << line;
        EXPECT_EQ(e.line->number, 2u) << line;
        EXPECT_EQ(p.host.lines_acknowledged(), 1u) << line;
        EXPECT_NE(p.host.failure_message().find(std::string("after line 2 '") + line + "'"), std::string::npos)
            << p.host.failure_message();
    }
}

TEST(HostFamilies, TeacupBootOkAndSilentM116) {
    // Teacup's boot "ok" answers nothing; M116 waits 5 s without output (a
    // long command: no timeout).
    Peer p("host_peer_teacup", FirmwareFamily::Teacup);
    p.host.add_lines("M104 S200\nM116\nG1 X10 F600\n");
    ASSERT_TRUE(p.host.run_until_finished(15.0)) << p.host.failure_message() << p.host.tail(12);
    EXPECT_EQ(p.host.lines_acknowledged(), 3u);
    EXPECT_EQ(p.host.oks(), 3u);  // the boot ok, before any line, answered nothing
    EXPECT_EQ(p.host.unsolicited_oks(), 0u);
    Cycle boot_ok = 0;
    for (const auto& e : p.host.transcript()) {
        if (e.direction == Direction::Received && e.text == "ok") {
            boot_ok = e.cycle;
            break;
        }
    }
    EXPECT_GT(boot_ok, 0u);
    EXPECT_LT(boot_ok, p.first_sent());
}

TEST(HostFamilies, GenericHostTakesBootChatterAsAnswers) {
    // Without a family the host sends at once: grbl's boot error:7 answers
    // line 1. This is why boards name their firmware's family.
    Peer p("host_peer_grbl", FirmwareFamily::Generic, FlowControl::CharacterCounting);
    p.host.add_lines("G21\n");
    p.host.run_until_finished(2.0);
    EXPECT_EQ(p.host.errors(), 1u);
}

}  // namespace
}  // namespace avrbench
