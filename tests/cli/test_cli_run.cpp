// `avrbench run`: the summary, the VCD it writes, and one clear line with exit
// code 2 for every kind of bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <ostream>

#include "support/Paths.hpp"
#include "support/RunCommand.hpp"
#include "trace/VcdReader.hpp"

namespace avrbench {
namespace {

using test::quoted;

const std::string kCli = ::avrbench::test::cli();

std::size_t line_count(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

TEST(CliRun, BlinkWritesAVcdThatReadsBackWithTheTimerPeriod) {
    const auto dir = test::scratch_dir("cli-blink");
    const auto vcd = (dir / "blink.vcd").string();
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("blink_timer1")) +
                                         " --for 10ms --trace-only PB5,PB1 --vcd " + quoted(vcd), dir);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    // 10 ms at 16 MHz = 160000 cycles; the run stops at the first
    // instruction boundary at or after it (instructions take up to 5 cycles).
    EXPECT_NE(r.out.find("simulated  0.0100"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(" (16000"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("findings   0"), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(dir / "blink.gtkw"));

    const VcdDump parsed = read_vcd(vcd);
    const VcdVariable* oc1a = parsed.find("mcu.PB1");
    ASSERT_NE(oc1a, nullptr);
    // 1 ms between OC1A toggles (Timer1 CTC, (249+1)*64 cycles at 16 MHz).
    ASSERT_GT(parsed.timescale_fs, 0u);
    const std::uint64_t one_ms = 1'000'000'000'000ULL / parsed.timescale_fs;
    std::vector<std::uint64_t> toggles;
    for (std::size_t i = 1; i < oc1a->changes.size(); ++i) toggles.push_back(oc1a->changes[i].time);
    ASSERT_GE(toggles.size(), 9u);
    for (std::size_t i = 1; i < toggles.size(); ++i) EXPECT_EQ(toggles[i] - toggles[i - 1], one_ms);
}

TEST(CliRun, TwoRunsGiveByteIdenticalVcds) {
    const auto dir = test::scratch_dir("cli-determinism");
    for (const char* name : {"a.vcd", "b.vcd"}) {
        const auto r = test::run_command(kCli + " run " + quoted(test::firmware("uart_echo")) +
                                             " --for 5ms --uart-in " + quoted(test::source_path("tests/cli/echo_input.txt")) +
                                             " --vcd " + quoted((dir / name).string()), dir);
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    const std::string a = test::slurp(dir / "a.vcd");
    ASSERT_GT(a.size(), 200u);
    EXPECT_EQ(a, test::slurp(dir / "b.vcd"));
}

// --simavr-core runs the same program on simavr's avr_run_one instead of
// mcu/PredecodedCore: the same VCD byte for byte, on a board job with
// five MCUs (the printer demo's board, a short job) and on one MCU.
TEST(CliRun, SimavrCoreGivesTheSameVcdAsThePredecodedCore) {
    const auto dir = test::scratch_dir("cli-simavr-core");
    for (const char* core : {"", " --simavr-core"}) {
        const std::string tag = *core ? "simavr" : "predecoded";
        const auto one = test::run_command(kCli + " run " + quoted(test::firmware("uart_echo")) +
                                               " --for 5ms --uart-in " + quoted(test::source_path("tests/cli/echo_input.txt")) +
                                               " --vcd " + quoted((dir / (tag + "-one.vcd")).string()) + core, dir);
        ASSERT_EQ(one.exit_code, 0) << one.err;
        const std::string fw = std::string(::avrbench::test::firmware_dir()) + "/";
        const auto board = test::run_command(
            kCli + " run " + quoted(fw + "printer3d_interp.elf") + " --board " +
                quoted(test::source_path("bench/boards/printer3d-seed001.yaml")) + " --firmware drive_x=" +
                quoted(fw + "printer3d_drive.elf") + " --firmware drive_y=" + quoted(fw + "printer3d_drive.elf") +
                " --firmware drive_z=" + quoted(fw + "printer3d_drive.elf") + " --firmware drive_e=" +
                quoted(fw + "printer3d_drive.elf") + " --firmware heater=" + quoted(fw + "printer3d_heater.elf") +
                " --for 300ms --vcd " + quoted((dir / (tag + "-board.vcd")).string()) + core,
            dir);
        ASSERT_EQ(board.exit_code, 0) << board.err;
    }
    for (const char* which : {"-one.vcd", "-board.vcd"}) {
        const std::string a = test::slurp(dir / (std::string("predecoded") + which));
        ASSERT_GT(a.size(), 200u) << which;
        EXPECT_TRUE(a == test::slurp(dir / (std::string("simavr") + which))) << which << " differs";
    }
}

// Marlin's resend protocol with a line the firmware rejects every time: a
// lone `*` is a checksum with no line before it, so seed 001's interpolator
// answers "Error:checksum mismatch", "Resend: 1", "ok" each time (its
// protocol, Printer3dJob.ProtocolChecksumsLineNumbersAndErrors). The host
// resends it 5 times (UartHost's limit) and then gives up with one line,
// instead of resending until --for ends (found by fuzzing: 1 750 resends in
// 6 s), and M114 after it is never sent.
TEST(CliRun, AHostGivesUpOnALineTheFirmwareRejectsEveryTime) {
    const auto dir = test::scratch_dir("cli-resend-loop");
    const auto job = dir / "job.gcode";
    std::ofstream(job) << "G91\n*\nM114\n";
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("printer3d_interp")) + " --board " +
                                         quoted(test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-alone.yaml")) +
                                         " --gcode " + quoted(job.string()) + " --for 5s",
                                     dir);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("line 2 '*' was asked for again 5 times in a row ('Resend: 1')"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("host-failed"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("> M114"), std::string::npos) << r.out;
    std::size_t resent = 0;
    for (std::size_t at = r.out.find("> *"); at != std::string::npos; at = r.out.find("> *", at + 1)) ++resent;
    EXPECT_LE(resent, 6u) << r.out;  // the transcript tail shows at most the first send and 5 resends
}

// A firmware that halts with "fatal:" (a homing failure) ends the job with
// exit 1 and one line naming the job's line, instead of "3 of 3
// acknowledged" and exit 0 (firmware/host_peer, the Marlin family's peer).
TEST(CliRun, AFatalMessageEndsTheJobWithExitCode1) {
    const auto dir = test::scratch_dir("cli-fatal");
    const auto job = dir / "job.gcode";
    std::ofstream(job) << "G1 X1\nFATAL\nG1 X2\n";
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("host_peer_marlin")) +
                                         " --board arduino-uno --family marlin --gcode " + quoted(job.string()) + " --for 20s",
                                     dir);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("firmware fatal error 'fatal:Homing failed!' after line 2 'FATAL'"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("1 of 3 lines acknowledged"), std::string::npos) << r.out;
}

// The motion oracle's summary says why it judged nothing: a job without a
// move, or no job at all (dda_line answers "ok" to any line that is not a G1).
TEST(CliRun, TheOracleSaysWhyItJudgedNothing) {
    const auto dir = test::scratch_dir("cli-oracle-nothing");
    std::ofstream(dir / "board.yaml") << "board: t\nextends: arduino-uno-cnc-shield-v3\nparts:\n"
                                         "  host: {type: serial_host, flow: send_and_wait, family: generic}\n";
    std::ofstream(dir / "job.gcode") << "M105\nM114\n";
    const std::string run = kCli + " run " + quoted(test::firmware("dda_line")) + " --board " + quoted((dir / "board.yaml").string());
    const auto with_job = test::run_command(run + " --gcode " + quoted((dir / "job.gcode").string()) + " --for 5s", dir);
    EXPECT_EQ(with_job.exit_code, 0) << with_job.out << with_job.err;
    EXPECT_NE(with_job.out.find("motion: 0 moves judged, 0 findings; the job commanded no move\n"), std::string::npos) << with_job.out;
    const auto without = test::run_command(run + " --for 10ms", dir);
    EXPECT_EQ(without.exit_code, 0) << without.out << without.err;
    EXPECT_NE(without.out.find("motion: 0 moves judged, 0 findings; nothing was commanded through the bench (no G-code job;"),
              std::string::npos)
        << without.out;
}

TEST(CliRun, UartInAndOut) {
    const auto dir = test::scratch_dir("cli-uart");
    const auto out = dir / "out.txt";
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("uart_echo")) + " --for 10ms --uart-in " +
                                         quoted(test::source_path("tests/cli/echo_input.txt")) + " --uart-out " +
                                         quoted(out.string()), dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(test::slurp(out), "avrbench uart_echo\r\n" + test::slurp(test::source_path("tests/cli/echo_input.txt")));
}

TEST(CliRun, UntilSleepStopsAtTheFirstSleep) {
    const auto dir = test::scratch_dir("cli-sleep");
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("sleep_idle")) + " --until-sleep", dir);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("firmware executed SLEEP"), std::string::npos) << r.out;
}

TEST(CliRun, FirmwareThatNeverSleepsTimesOutWithCode3) {
    const auto dir = test::scratch_dir("cli-nosleep");
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("busy_poll")) + " --until-sleep --for 5ms", dir);
    EXPECT_EQ(r.exit_code, 3);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("did not execute SLEEP within 5ms"), std::string::npos) << r.err;
}

TEST(CliRun, CrashIsAFindingWithExitCode1) {
    const auto dir = test::scratch_dir("cli-crash");
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("crash_bad_opcode")), dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.out.find("invalid-opcode"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("bad_opcode_here"), std::string::npos) << r.out;
}

struct BadInputCase {
    const char* name;
    std::string args;
    std::string expected_fragment;
};

// Keeps ctest's test names short: gtest would otherwise print the raw bytes.
void PrintTo(const BadInputCase& c, std::ostream* os) { *os << c.name; }

class CliBadInput : public ::testing::TestWithParam<BadInputCase> {};

TEST_P(CliBadInput, OneLineAndExitCode2) {
    const auto dir = test::scratch_dir(std::string("cli-bad-") + GetParam().name);
    const auto r = test::run_command(kCli + " " + GetParam().args, dir);
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(GetParam().expected_fragment), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
}

INSTANTIATE_TEST_SUITE_P(
    AllErrors, CliBadInput,
    ::testing::Values(
        BadInputCase{"missing_file", "run /nonexistent/fw.elf", "/nonexistent/fw.elf: no such file"},
        BadInputCase{"not_elf", "run " + test::source_path("tests/cli/echo_input.txt"), "echo_input.txt: not an ELF file"},
        BadInputCase{"not_avr", "run " + std::string(::avrbench::test::cli()), "not an AVR ELF"},
        BadInputCase{"unknown_mcu", "run " + test::firmware("blink_timer1") + " --mcu atmega9999",
                     "unknown MCU 'atmega9999'"},
        // Both options missing are named in one message, so one correction suffices.
        BadInputCase{"no_mmcu", "run " + test::firmware("blink_timer1_nommcu"), "give both with --mcu and --freq"},
        BadInputCase{"no_mmcu_freq_given", "run " + test::firmware("blink_timer1_nommcu") + " --freq 16MHz", "give one with --mcu"},
        BadInputCase{"no_mmcu_mcu_given", "run " + test::firmware("blink_timer1_nommcu") + " --mcu atmega328p", "give one with --freq"},
        BadInputCase{"bad_duration", "run " + test::firmware("blink_timer1") + " --for 2parsecs", "--for"},
        BadInputCase{"bad_freq", "run " + test::firmware("blink_timer1") + " --freq fast", "--freq"},
        BadInputCase{"missing_uart_in", "run " + test::firmware("uart_echo") + " --uart-in /nonexistent/in.txt",
                     "/nonexistent/in.txt"},
        BadInputCase{"unknown_pin", "run " + test::firmware("blink_timer1") + " --trace PZ3", "PZ3"},
        BadInputCase{"unknown_option", "run " + test::firmware("blink_timer1") + " --frobnicate", "usage error"},
        BadInputCase{"no_subcommand", "", "usage error"},
        BadInputCase{"realtime_without_board", "run " + test::firmware("blink_timer1") + " --realtime 1s=!",
                     "--realtime needs --board and --gcode"},
        BadInputCase{"realtime_without_gcode",
                     "run " + test::firmware("blink_timer1") + " --board arduino-uno-cnc-shield-v3 --realtime 1s=!",
                     "--realtime needs --gcode"},
        BadInputCase{"realtime_malformed",
                     "run " + test::firmware("blink_timer1") + " --board arduino-uno-cnc-shield-v3 --realtime 1s",
                     "expected TIME=BYTES"},
        BadInputCase{"realtime_non_ascii_byte",
                     "run " + test::firmware("blink_timer1") + " --board arduino-uno-cnc-shield-v3 --realtime 1s=\xc3\xa9",
                     "write control bytes as ^X or 0xNN"}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(CliRun, FirmwareForABiggerMcuCrashesCleanly) {
    // The Mega 2560 start-up code sets SP to 0x21FF; on an ATtiny85 (RAMEND
    // 0x25F) the first push writes outside RAM. simavr reports it; the bench
    // turns it into a finding instead of letting the write hit host memory.
    const auto dir = test::scratch_dir("cli-wrong-mcu");
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("blink_timer1_m2560")) + " --mcu attiny85", dir);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.out.find("simavr-crash"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("out of ram"), std::string::npos) << r.out;
}

TEST(CliRun, ElfWithoutMmcuRunsWithMcuAndFreq) {
    const auto dir = test::scratch_dir("cli-nommcu");
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("blink_timer1_nommcu")) +
                                         " --mcu atmega328p --freq 16MHz --for 2ms", dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("atmega328p at 16 MHz"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// heat_wait on RAMPS 1.4 (firmware/boards/heat_wait): the bed's Timer4 fast
// PWM at clk/1 with OCR4C = 0 is "a narrow spike for each MAX+1 timer clock
// cycle" (2560 §17.9.3): high 1 cycle in 256. Nothing records the bed pin
// here, so it reaches the bed heater as a periodic wave and the summary's
// "W now" is its mean power: the bed_12v preset's 12 V on 1.2 ohm = 120 W,
// x 1/256 = 0.47 W. With --no-periodic-waves every spike goes through the
// net and the summary shows the instantaneous power, 0 W (the pin is low in
// 255 of 256 cycles; the run ends on a low one). Either way the bed gets
// 0.47 J in the second: 3 mK on its 158 J/K, so 25.00 degC on both.
TEST(CliRunPeriodicWaves, ADutyZeroBedHeatsWithItsMeanPowerUnlessWavesAreOff) {
    const auto dir = test::scratch_dir("periodic-waves");
    const std::string base =
        ::avrbench::test::cli() + std::string(" run -q --board ramps-1.4 ") + test::firmware("heat_wait") + " --for 1s";
    const auto waves = test::run_command(base, dir);
    const auto edges = test::run_command(base + " --no-periodic-waves", dir);
    ASSERT_EQ(waves.exit_code, 0) << waves.out << waves.err;
    ASSERT_EQ(edges.exit_code, 0) << edges.out << edges.err;
    EXPECT_NE(waves.out.find("thermal    bed: block 25.00 degC, sensor 25.00 degC, heater 0.5 W now"), std::string::npos)
        << waves.out;
    EXPECT_NE(edges.out.find("thermal    bed: block 25.00 degC, sensor 25.00 degC, heater 0.0 W now"), std::string::npos)
        << edges.out;
    // The hot end heater's OC2A sits at duty 255 (cold: the controller asks
    // for full power), a constant-high wave: 40 W either way.
    EXPECT_NE(waves.out.find("heater 40.0 W now"), std::string::npos) << waves.out;
    EXPECT_NE(edges.out.find("heater 40.0 W now"), std::string::npos) << edges.out;
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(CliRun, TraceOnlyTakesPartSignalsAndNetNamesAsTheVcdNamesThem) {
    const auto dir = test::scratch_dir("cli-trace-part");
    const auto vcd = (dir / "t.vcd").string();
    // arduino-uno-cnc-shield-v3: net x_step joins uno.PD2 (grbl's X_STEP); the
    // linear axis x declares the signal position_mm.
    const auto r = test::run_command(kCli + " run -q --board arduino-uno-cnc-shield-v3 " + quoted(test::firmware("stepdir_test")) +
                                         " --for 20ms --trace-only x.position_mm,x_step --vcd " + quoted(vcd), dir);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const VcdDump parsed = read_vcd(vcd);
    std::vector<std::string> names;
    for (const auto& v : parsed.variables) names.push_back(v.full_name());
    EXPECT_EQ(names, (std::vector<std::string>{"uno.PD2", "x.position_mm", "nets.x_step"}));

    const auto bad = test::run_command(kCli + " run -q --board arduino-uno-cnc-shield-v3 " + quoted(test::firmware("stepdir_test")) +
                                           " --for 20ms --trace-only x.speed --vcd " + quoted(vcd), dir);
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_EQ(bad.err, "avrbench: error: --trace-only: part 'x' has no signal 'speed' (signals: position_mm)\n");
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(CliRun, UntilSleepOnASleepWithInterruptsOffSaysTheCoreHaltedNotTheTimeLimit) {
    // firmware/boards/tmc2130_driver ends in sleep_mode() with interrupts
    // never enabled: the core halts at that SLEEP, long before --for's 1 s.
    const auto dir = test::scratch_dir("cli-until-sleep-halt");
    const auto r = test::run_command(kCli + " run " + quoted(test::firmware("tmc2130_driver")) +
                                         " --mcu atmega2560 --freq 16MHz --until-sleep --for 1s", dir);
    EXPECT_NE(r.out.find("  stopped    the core halted (below)\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("  halted     SLEEP with interrupts disabled"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("time limit"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// A port carrying a binary protocol is shown as bytes, not as escaped
// "lines": uart_echo's banner "avrbench uart_echo\r\n" (20 bytes, ASCII)
// then two frames of ours echoed back, each ending at 0x7E (Klipper's sync
// byte), one per line.
TEST(CliRun, ABinaryPortIsSummarisedAsFramesInHex) {
    const auto dir = test::scratch_dir("binary-port");
    std::ofstream(dir / "frames.bin", std::ios::binary) << std::string("\x05\x10\x81\x22\x9a\x7e\x06\x11\x81\x33\x44\x7e", 12);
    const auto r = test::run_command(std::string(test::cli()) + " run " + test::quoted(test::firmware("uart_echo")) + " --board " +
                                         test::source_path("bench/boards/arduino-uno.yaml") + " --uart-in " +
                                         (dir / "frames.bin").string() + " --for 0.1s", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("  serial host 32 bytes from firmware, 12 bytes to firmware:\n"
                         "    (binary: 32 bytes; the last 32 in hex)\n"
                         "    61 76 72 62 65 6e 63 68 20 75 61 72 74 5f 65 63 68 6f 0d 0a 05 10 81 22 9a 7e\n"
                         "    06 11 81 33 44 7e\n"),
              std::string::npos)
        << r.out;
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// A mistyped option or subcommand: the usage error names the one meant.
TEST(CliUsage, ATypoGetsTheNearestOptionOrSubcommand) {
    const auto dir = test::scratch_dir("cli-typo");
    const std::string cli = std::string(test::cli());
    const auto option = test::run_command(cli + " run x.elf --gcod job.g", dir);
    EXPECT_EQ(option.exit_code, 2);
    EXPECT_EQ(option.err, "avrbench: usage error: The following arguments were not expected: job.g --gcod; did you mean "
                          "--gcode? (see avrbench --help)\n");
    const auto sub = test::run_command(cli + " runn x.elf", dir);
    EXPECT_EQ(sub.exit_code, 2);
    EXPECT_EQ(sub.err, "avrbench: usage error: A subcommand is required; did you mean 'run'? (see avrbench --help)\n");
    const auto nested = test::run_command(cli + " board from-confg x.h", dir);
    EXPECT_NE(nested.err.find("did you mean 'from-config'?"), std::string::npos) << nested.err;
    // Nothing near: no guess.
    const auto far = test::run_command(cli + " zzzzzz", dir);
    EXPECT_EQ(far.err, "avrbench: usage error: A subcommand is required (see avrbench --help)\n");
}

// A board MCU left without firmware: the message says how to give it one.
TEST(CliUsage, AnMcuWithoutFirmwareSaysHowToGiveIt) {
    const auto dir = test::scratch_dir("cli-no-firmware");
    const auto r = test::run_command(std::string(test::cli()) + " run " + test::quoted(test::firmware("printer3d_interp")) +
                                         " --board printer3d-seed001", dir);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("MCU 'drive_x' has no firmware: give it one (run --firmware drive_x=ELF"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace avrbench
