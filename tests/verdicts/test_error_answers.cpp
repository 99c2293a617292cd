// False greens: a firmware's error answer must never count as an answer.
// Each family's error lines, as its own sources print them (quoted in
// firmware/host_peer/main.c and docs/HOSTS.md), are counted as errors, name
// the line they are about and become host-protocol findings; lines go out
// byte for byte as written.
#include <gtest/gtest.h>

#include "mcu/Mcu.hpp"
#include "stimulus/UartHost.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

struct Peer {
    Mcu mcu;
    UartHost host;
    Peer(const std::string& family_name, FirmwareFamily family)
        : mcu(ElfImage::load(test::firmware("host_peer_" + family_name))), host(mcu, 0, options(family)) {}
    static UartHostOptions options(FirmwareFamily family) {
        UartHostOptions o;
        o.family = family;
        return o;
    }
};

struct Case {
    const char* firmware;
    FirmwareFamily family;
    const char* error_line;  // what the family prints for line 2, "M9999"
};

// One known command, one unknown, one known: exactly the middle line is an
// error, and the job still ends (every line answered).
void expect_one_error_on_the_middle_line(const Case& c) {
    SCOPED_TRACE(c.firmware);
    Peer p(c.firmware, c.family);
    p.host.add_lines("G90\nM9999\nG1 X1\n");
    ASSERT_TRUE(p.host.run_until_finished(15.0)) << p.host.tail(12);
    // Repetier reports an unknown command when it runs, after its ok: give
    // it the 2 ms host_peer's queue takes.
    p.mcu.run_until(p.mcu.cycle() + p.mcu.cycles_from_seconds(0.01));
    EXPECT_TRUE(p.host.done()) << p.host.failure_message();
    EXPECT_EQ(p.host.lines_acknowledged(), 3u);
    EXPECT_EQ(p.host.errors(), 1u) << p.host.tail(12);
    EXPECT_EQ(p.host.lines_errored(), 1u);
    EXPECT_FALSE(p.host.line_errored(0));
    EXPECT_TRUE(p.host.line_errored(1));
    EXPECT_FALSE(p.host.line_errored(2));
    ASSERT_EQ(p.host.events().size(), 1u);
    const HostEvent& e = p.host.events()[0];
    EXPECT_EQ(e.kind, HostEventKind::Error);
    EXPECT_EQ(e.response, c.error_line);
    ASSERT_TRUE(e.line.has_value());
    EXPECT_EQ(e.line->number, 2u);
    EXPECT_EQ(e.message, std::string("line 2 'M9999' got '") + c.error_line + "'");
}

TEST(ErrorAnswers, MarlinUnknownCommandBeforeItsOkIsAnError) {
    // Marlin 1.0/1.1: SERIAL_ECHO_START; MSG_UNKNOWN_COMMAND; the line; "\"".
    expect_one_error_on_the_middle_line({"marlin", FirmwareFamily::Marlin, "echo:Unknown command: \"M9999\""});
}

TEST(ErrorAnswers, PrusaUnknownCodeIsAnError) {
    // Prusa-Firmware: printf_P(MSG_UNKNOWN_CODE, 'M', ...), "Unknown %c code: %s".
    expect_one_error_on_the_middle_line({"prusa", FirmwareFamily::Prusa, "Unknown M code: M9999"});
}

TEST(ErrorAnswers, TeacupBadMCodeIsAnError) {
    // Teacup gcode_process.c: sersendf_P(PSTR("E: Bad M-code %d\n"), ...).
    expect_one_error_on_the_middle_line({"teacup", FirmwareFamily::Teacup, "E: Bad M-code 9999"});
}

TEST(ErrorAnswers, SprinterUnknownMComIsAnError) {
    // Sprinter.pde (SEND_WRONG_CMD_INFO): "Unknown M-COM:" and the line.
    expect_one_error_on_the_middle_line({"sprinter", FirmwareFamily::Sprinter, "Unknown M-COM:M9999"});
}

TEST(ErrorAnswers, RepetierUnknownCommandAfterItsOkIsAboutThatLine) {
    // Repetier answers ok when a line is queued and prints "Unknown command:"
    // with the command when it runs: by then line 3 may be out; the error
    // names M9999, so it is about line 2.
    expect_one_error_on_the_middle_line({"repetier", FirmwareFamily::Repetier, "Unknown command:M9999 "});
}

TEST(ErrorAnswers, TeacupBadGCodeNamesItsLineByNumber) {
    // "E: Bad G-code 5" names G5: the line is found by its command word.
    Peer p("teacup", FirmwareFamily::Teacup);
    p.host.add_lines("G5 X1\nG1 X1\n");
    ASSERT_TRUE(p.host.run_until_finished(10.0)) << p.host.tail(10);
    ASSERT_EQ(p.host.events().size(), 1u);
    EXPECT_EQ(p.host.events()[0].message, "line 1 'G5 X1' got 'E: Bad G-code 5'");
}

TEST(ErrorAnswers, SprinterSerialErrorCountsAsAnErrorAndTheResentLineIsOk) {
    // Sprinter's "Serial Error: Line Number is not Last Line Number+1" then
    // "Resend:1" and "ok": one error answer (as Marlin's "Error:checksum
    // mismatch" is), the line sent again and then answered ok.
    Peer p("sprinter", FirmwareFamily::Sprinter);
    p.host.add_lines("N1 G1 X1*99\n");
    ASSERT_TRUE(p.host.run_until_finished(10.0)) << p.host.tail(10);
    EXPECT_TRUE(p.host.done()) << p.host.failure_message();
    EXPECT_EQ(p.host.errors(), 1u);
    EXPECT_EQ(p.host.resends(), 1u);
    EXPECT_EQ(p.host.lines_errored(), 0u);  // taken the second time
}

TEST(ErrorAnswers, TeacupResendRequestIsAnErrorAndTheLineGoesAgain) {
    // Teacup's "rs N1 Expected checksum 17" then "ok": the line was not
    // run; sent again (host_peer refuses "*99" the first time only, as a
    // line garbled on the way would be) it is taken.
    Peer p("teacup", FirmwareFamily::Teacup);
    p.host.add_lines("N1 G1 X1*99\n");
    ASSERT_TRUE(p.host.run_until_finished(10.0)) << p.host.tail(10);
    EXPECT_TRUE(p.host.done()) << p.host.failure_message();
    EXPECT_EQ(p.host.errors(), 1u);
    EXPECT_EQ(p.host.resends(), 1u);
    EXPECT_EQ(p.host.lines_errored(), 0u);
}

TEST(ErrorAnswers, AUserPatternMarksAGenericFirmwaresErrorLine) {
    // The generic family knows "ok" and "error..." only; a user pattern for
    // a message the firmware prints makes it an error too (host_peer_sprinter's
    // "Unknown M-COM:", before its ok).
    UartHostOptions o;
    o.family = FirmwareFamily::Generic;
    o.startup = Startup::WaitForBanner;
    o.banner_contains = "start";
    o.error_patterns = {"^Unknown [GM]-COM:"};
    Mcu mcu(ElfImage::load(test::firmware("host_peer_sprinter")));
    UartHost host(mcu, 0, o);
    host.add_lines("G90\nM9999\n");
    ASSERT_TRUE(host.run_until_finished(10.0)) << host.tail(10);
    EXPECT_EQ(host.errors(), 1u) << host.tail(10);
    EXPECT_TRUE(host.line_errored(1));
}

TEST(ErrorAnswers, ABadUserPatternIsBadInput) {
    UartHostOptions o;
    o.error_patterns = {"(unclosed"};
    Mcu mcu(ElfImage::load(test::firmware("host_peer_teacup")));
    try {
        UartHost host(mcu, 0, o);
        FAIL() << "no exception";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("error pattern: '(unclosed' is not a regular expression"), std::string::npos)
            << e.what();
    }
}

TEST(ErrorAnswers, TrailingBlanksAreSentAsWritten) {
    // A 140-byte line of which the last two are blanks: 140 bytes and the
    // newline reach the firmware (host_peer_marlin reads up to 95 bytes of a
    // line and counts nothing: the UART's own count is the check).
    Peer p("marlin", FirmwareFamily::Marlin);
    const std::string line = "G1 X" + std::string(134, '1') + "  ";
    ASSERT_EQ(line.size(), 140u);
    p.host.add_lines(line + "\n");
    ASSERT_TRUE(p.host.run_until_finished(15.0)) << p.host.tail(6);
    EXPECT_EQ(p.mcu.uart(0).bytes_delivered(), 141u);
    EXPECT_EQ(p.host.lines()[0].text, line);
}

TEST(ErrorAnswers, TheRunSummaryCountsTheErrorAndStrictFailsOnIt) {
    // The CLI on the UNO board, Marlin's family: "4 ok, 1 error", a
    // host-protocol finding naming line 2, exit 0 as documented (host
    // errors fail only with --strict, docs/CLI.md) and 1 with --strict.
    const auto dir = test::scratch_dir("verdict-error-answers");
    {
        std::ofstream job(dir / "job.gcode");
        job << "G90\nM9999\nG1 X1\nM105\n";
    }
    const std::string cmd = std::string(test::cli()) + " run " + test::quoted(test::firmware("host_peer_marlin")) +
                            " --board arduino-uno --family marlin --gcode " + test::quoted((dir / "job.gcode").string()) +
                            " --for 20s";
    const auto r = test::run_command(cmd, dir);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("4 of 4 lines acknowledged (4 ok, 1 error)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("line 2 'M9999' got 'echo:Unknown command: \"M9999\"'"), std::string::npos) << r.out;
    const auto strict = test::run_command(cmd + " --strict", dir);
    EXPECT_EQ(strict.exit_code, 1) << strict.out << strict.err;
}

}  // namespace
}  // namespace avrbench
