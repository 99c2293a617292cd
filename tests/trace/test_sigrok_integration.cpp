// sigrok (sigrok-cli, the command-line face of PulseView's libsigrok and
// libsigrokdecode) must read the VCDs `avrbench run` writes: to their end,
// every signal, and its protocol decoders must find in them what the bench
// itself reports. Debian's sigrok-cli 0.7 / libsigrok 0.5 reads 1-bit signals
// only and stops at the first vector value, which is why buses are written
// as one wire per bit by default (VcdBuses::Bits).
//
// sigrok-cli comes from ci/setup; a missing tool fails the test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "periph/twi/Twi.hpp"
#include "printer3d/PrinterBench.hpp"
#include "support/Paths.hpp"
#include "trace/VcdWriter.hpp"
#include "support/PinLog.hpp"
#include "trace/TraceTestSupport.hpp"

namespace avrbench {
namespace {

using trace_test::quoted;
using trace_test::read_text;
using trace_test::ScratchDir;

std::string sigrok_cli() {
    const std::string path = trace_test::find_program("sigrok-cli");
    if (path.empty()) ADD_FAILURE() << "sigrok-cli not found on PATH: run ci/setup (it installs Debian's sigrok-cli)";
    return path;
}

// Runs sigrok-cli on `vcd` with `arguments`; its standard output. The VCD's
// unit is 100 ps: downsample=625 gives one sample per 16 MHz cycle.
std::string sigrok(const ScratchDir& dir, const std::string& vcd, const std::string& arguments) {
    const std::string out = dir.file("sigrok.out");
    const int status = trace_test::run_command(
        "timeout 120 " + quoted(sigrok_cli()) + " -I vcd:downsample=625 -i " + quoted(vcd) + " " + arguments, out);
    EXPECT_EQ(status, 0) << read_text(out);
    return read_text(out);
}

// The bytes of the UART decoder's "uart-1: 61" lines.
std::string decoded_bytes(const std::string& sigrok_output) {
    std::string bytes;
    std::istringstream lines(sigrok_output);
    std::string line;
    while (std::getline(lines, line)) {
        const auto colon = line.find(": ");
        if (line.rfind("uart-", 0) != 0 || colon == std::string::npos) continue;
        bytes.push_back(static_cast<char>(std::stoi(line.substr(colon + 2), nullptr, 16)));
    }
    return bytes;
}

// uart_echo at 115200 baud with U2X (UBRR = 16: 16 MHz / (8 x 17) = 117 647
// baud, §20.3.1 Table 20-1; the decoder is given that rate): sigrok's UART
// decoder on TXD (PD1) reads exactly what --uart-out wrote, and on RXD (PD0)
// exactly what --uart-in sent.
TEST(SigrokReadsOurVcd, UartDecoderOnTxdAndRxdMatchesTheBytes) {
    ScratchDir dir;
    const std::string input = "hello, sigrok\n";
    trace_test::write_text(dir.file("in.txt"), input);
    const int status = trace_test::run_command(
        quoted(::avrbench::test::cli()) + " run -q " + quoted(test::firmware("uart_echo")) + " --for 5ms --uart-in " +
            quoted(dir.file("in.txt")) + " --uart-out " + quoted(dir.file("out.txt")) + " --vcd " + quoted(dir.file("u.vcd")),
        dir.file("run.log"));
    ASSERT_EQ(status, 0) << read_text(dir.file("run.log"));
    const std::string sent_by_firmware = read_text(dir.file("out.txt"));
    ASSERT_GT(sent_by_firmware.size(), input.size());  // banner + echo
    // 5 ms at 16 MHz: 80 000 samples; libsigrok read the whole file.
    EXPECT_NE(sigrok(dir, dir.file("u.vcd"), "--show").find("Logic sample count: 80000\n"), std::string::npos);
    EXPECT_EQ(decoded_bytes(sigrok(dir, dir.file("u.vcd"), "-P uart:rx=PD1:baudrate=117647 -A uart=rx-data")),
              sent_by_firmware);
    EXPECT_EQ(decoded_bytes(sigrok(dir, dir.file("u.vcd"), "-P uart:rx=PD0:baudrate=117647 -A uart=rx-data")), input);
}

// A two-MCU board, Wire master on an UNO and slave on a Mega (the sketches
// of ArduinoCore.WireMasterAndSlaveOnTwoMcus): sigrok reads the dump to its
// end, lists each board net under its board-file name, and its I2C decoder on
// the nets `sda` and `scl` finds the sketches' transactions. Expected from
// wire_master.cpp / wire_slave.cpp: every 20 ms a write of "n=<round>" to
// address 8, then a read of 6 bytes "ok#<writes seen>..", the master NACKing
// the last (I2C: a master receiver ends a read with NACK; §22.7.2).
TEST(SigrokReadsOurVcd, I2cDecoderOnTheBoardNetsFindsTheSketchesTransactions) {
    ScratchDir dir;
    trace_test::write_text(dir.file("wire.yaml"),
                           "mcus:\n"
                           "  uno: {type: atmega328p, clock: 16MHz}\n"
                           "  mega: {type: atmega2560, clock: 16MHz}\n"
                           "nets:\n"
                           "  sda: [uno.PC4, mega.PD1]\n"
                           "  scl: [uno.PC5, mega.PD0]\n");
    const int status = trace_test::run_command(
        quoted(::avrbench::test::cli()) + " run -q --board " + quoted(dir.file("wire.yaml")) + " " +
            quoted(test::firmware("ard_wire_master")) + " --firmware mega=" + quoted(test::firmware("ard_wire_slave_mega")) +
            " --for 70ms --vcd " + quoted(dir.file("w.vcd")),
        dir.file("run.log"));
    ASSERT_EQ(status, 0) << read_text(dir.file("run.log"));
    // The summary counts the same traffic: 3 rounds of a write ("n=<r>", 3
    // bytes) and a read (6 bytes); the master's NACK of its last read byte is
    // no slave's NACK.
    EXPECT_NE(read_text(dir.file("run.log")).find("i2c        uno as master: 6 transfers, 27 data bytes, 0 NACKed by a slave\n"),
              std::string::npos)
        << read_text(dir.file("run.log"));
    const std::string shown = sigrok(dir, dir.file("w.vcd"), "--show");
    EXPECT_NE(shown.find("Logic sample count: 1120000\n"), std::string::npos) << shown;  // 70 ms x 16 MHz
    EXPECT_NE(shown.find("- sda: logic\n"), std::string::npos) << shown;
    EXPECT_NE(shown.find("- scl: logic\n"), std::string::npos) << shown;
    EXPECT_NE(shown.find("- twi[7]: logic\n"), std::string::npos) << shown;  // a bus, as bits

    std::string expected;
    auto hex = [](char c) {
        char text[3];
        std::snprintf(text, sizeof text, "%02X", static_cast<unsigned char>(c));
        return std::string(text);
    };
    // Rounds at about 20, 40 and 60 ms: three in 70 ms.
    for (int round = 0; round < 3; ++round) {
        expected += "Start|Write|Address write: 08|ACK|";  // the R/W bit is its own annotation
        for (char c : "n=" + std::to_string(round)) expected += "Data write: " + hex(c) + "|ACK|";
        expected += "Stop|Start|Read|Address read: 08|ACK|";
        const std::string reply = "ok#" + std::to_string(round + 1) + "..";
        for (std::size_t i = 0; i < reply.size(); ++i)
            expected += "Data read: " + hex(reply[i]) + (i + 1 < reply.size() ? "|ACK|" : "|NACK|");
        expected += "Stop|";
    }
    const std::string decoded =
        sigrok(dir, dir.file("w.vcd"),
               "-P i2c:scl=scl:sda=sda -A i2c=start:repeat-start:stop:ack:nack:address-read:address-write:data-read:data-write");
    std::string joined;
    std::istringstream lines(decoded);
    std::string line;
    while (std::getline(lines, line)) {
        if (line.rfind("i2c-1: ", 0) == 0) joined += line.substr(7) + "|";
    }
    EXPECT_EQ(joined, expected);
}

// Seed 001's five-MCU printer: the interpolator sets the hot end's target
// and reads its status over I2C and steps X. sigrok's I2C decoder on the
// board's `sda`/`scl` nets reads the same bytes the bench's TWI model
// exchanged (TwiEvent: SLA+R/W and data, in order), and its edge counter on
// the `x_step` net counts the rising edges the interpolator's STEP pin made.
TEST(SigrokReadsOurVcd, FiveMcuPrinterI2cBytesAndStepEdgesAgreeWithTheBench) {
    ScratchDir dir;
    auto bench = test::printer_bench();
    bench->trace_board();
    std::string bench_bytes;
    bench->mcu("interp").twi()->on_event([&bench_bytes](const TwiEvent& e) {
        char text[16];
        if (e.kind == TwiEvent::Kind::Address) {
            std::snprintf(text, sizeof text, "A%02X%c|", e.byte >> 1, (e.byte & 1) ? 'r' : 'w');
            bench_bytes += text;
        } else if (e.kind == TwiEvent::Kind::Data) {
            std::snprintf(text, sizeof text, "D%02X|", e.byte);
            bench_bytes += text;
        }
    });
    test::PinLog x_step(bench->mcu("interp"), "PA0");
    // M400: the move ends before the status; M104 S0: the heater off again,
    // so the run is done without waiting for 60 degC.
    bench->host().add_lines("M104 S60\nG1 X1 F600\nM400\nM105\nM104 S0\n");
    ASSERT_EQ(bench->run_until_idle(10.0), IdleResult::Idle) << bench->host().received_text();
    VcdOptions options;
    options.end_cycle = bench->mcu("interp").cycle();
    options.end_clock_hz = bench->mcu("interp").frequency_hz();
    write_vcd(bench->timeline(), dir.file("p.vcd"), options);
    ASSERT_GT(bench_bytes.size(), 20u);   // a set point and status reads at least
    ASSERT_GE(x_step.rises().size(), 90u);  // 1 mm at 100 steps/mm (the board's lead screws)

    // 16 MHz / 62.5 ns per sample (downsample 625): the 100 kHz I2C bus and
    // the STEP pulses are many samples wide.
    const std::string decoded =
        sigrok(dir, dir.file("p.vcd"), "-P i2c:scl=scl:sda=sda -A i2c=address-read:address-write:data-read:data-write");
    std::string sigrok_bytes;
    std::istringstream lines(decoded);
    std::string line;
    while (std::getline(lines, line)) {
        const auto colon = line.rfind(": ");
        // "i2c-1: Write" / "i2c-1: Read" (the R/W bit alone) carry no value.
        if (line.rfind("i2c-1: ", 0) != 0 || colon == std::string::npos || colon < 7) continue;
        const std::string value = line.substr(colon + 2);
        if (line.find("Address write") != std::string::npos) sigrok_bytes += "A" + value + "w|";
        else if (line.find("Address read") != std::string::npos) sigrok_bytes += "A" + value + "r|";
        else sigrok_bytes += "D" + value + "|";
    }
    EXPECT_EQ(sigrok_bytes, bench_bytes);
    // The report says so too: one fact with the byte count the TWI model made.
    const std::string count_fact =
        "I2C interp.twi: " + std::to_string(std::count(bench_bytes.begin(), bench_bytes.end(), '|')) + " bytes";
    const RunReport report = bench->make_report("printer");
    EXPECT_TRUE(std::any_of(report.facts.begin(), report.facts.end(),
                            [&](const std::string& f) { return f.rfind(count_fact, 0) == 0; }))
        << count_fact;

    const std::string counted =
        sigrok(dir, dir.file("p.vcd"), "-P counter:data=x_step:data_edge=rising -A counter=edge_count");
    // The counter annotates its running count at every edge; the last is the total.
    const auto last = counted.rfind("counter-1: ");
    ASSERT_NE(last, std::string::npos) << counted;
    EXPECT_EQ(std::stoul(counted.substr(last + 11)), x_step.rises().size()) << counted.substr(last);
}

}  // namespace
}  // namespace avrbench
