// Seed 001's printer as a host drives it: the G-code protocol of
// firmware/printer3d_interp (its header), the extruder and Z rules of §4.7
// and §4.8 (digest §10.13, §10.14), homing (§10.15), the heater link, and the
// thesis' parser as printed (THESIS_PARSER: a negative fixture, digest §9.8).
// Expected values: the G-code itself and the firmware's documented constants
// (100 BLU/mm, SP = 1/8 E step per tick, 40-step retract), worked out here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "parts/Axis.hpp"
#include "printer3d/PrinterBench.hpp"
#include "support/PinLog.hpp"

namespace avrbench {
namespace {



// Edges of `log` inside [from, to].
std::size_t count_between(const std::vector<Cycle>& edges, Cycle from, Cycle to) {
    return static_cast<std::size_t>(std::count_if(edges.begin(), edges.end(), [&](Cycle c) { return c >= from && c <= to; }));
}

TEST(Printer3dJob, ExtruderFollowsDepositingMovesAndZMovesAlone) {
    auto bench = test::powered_printer();
    Mcu& interp = bench->mcu("interp");
    test::PinLog x(interp, "PA0"), y(interp, "PA1"), z(interp, "PA2"), e(interp, "PA3"), e_dir(interp, "PC3");
    bench->host().add_lines("M3\nG1 X1 F500\nM400\nG0 X2\nM400\nG1 Z0.2\nM400\nG1 X1\nM5\nM400\n");
    ASSERT_EQ(bench->run_until_idle(20.0), IdleResult::Idle) << bench->host().received_text();
    // Ticks: G1 X1 = 100, G0 X2 = 100 (no extrusion), Z0.2 = 20, G1 X1 = 100.
    // E: prime +40, 100 ticks / 8 = 12 (4/8 left over), retract -40 before the
    // G0, prime +40 before the last G1, (4 + 100) / 8 = 13, retract -40 at M5.
    EXPECT_EQ(test::drive_position(*bench, "drive_e"), 40 + 12 - 40 + 40 + 13 - 40);
    EXPECT_EQ(e.rises().size(), 40u + 12u + 40u + 40u + 13u + 40u);
    EXPECT_EQ(test::drive_position(*bench, "drive_x"), 100);
    EXPECT_EQ(test::drive_position(*bench, "drive_z"), 20);  // §10.14: SZ = 0.2 mm * 100 steps/mm
    // §10.13/§10.14: no E step while G0 or Z move (the first X step of the G0 to its last; the Z steps).
    ASSERT_EQ(x.rises().size(), 300u);
    const Cycle g0_from = x.rises()[100], g0_to = x.rises()[199];
    EXPECT_EQ(count_between(e.rises(), g0_from, g0_to), 0u);
    ASSERT_EQ(z.rises().size(), 20u);
    const Cycle z_from = z.rises().front(), z_to = z.rises().back();
    EXPECT_EQ(count_between(e.rises(), z_from, z_to), 0u);
    EXPECT_EQ(count_between(x.rises(), z_from, z_to), 0u);  // nothing else moves with Z
    EXPECT_EQ(count_between(y.rises(), z_from, z_to), 0u);
    // The retract runs backwards: DIR low before its first step.
    bool saw_reverse = false;
    for (const auto& edge : e_dir.edges()) saw_reverse = saw_reverse || !edge.level;
    EXPECT_TRUE(saw_reverse);
    for (const Finding& f : bench->findings()) ADD_FAILURE() << f.source << ": " << f.detail;
}

TEST(Printer3dJob, HomingStopsEachAxisOnItsSwitch) {
    auto bench = test::powered_printer();
    bench->host().add_lines("G28\nM114\n");
    ASSERT_EQ(bench->run_until_idle(20.0), IdleResult::Idle) << bench->host().received_text();
    // The carriages started 3.5 / 2.5 / 1.5 mm from the stop; the switches
    // trip at 0.5 mm (0.05 mm hysteresis), one full step = 0.01 mm.
    for (const char* axis : {"x", "y", "z"}) {
        EXPECT_NEAR(bench->axis(axis).position_mm(), 0.5, 0.02) << axis;
    }
    EXPECT_NEAR(test::drive_position(*bench, "drive_x"), -300, 2);
    EXPECT_NEAR(test::drive_position(*bench, "drive_y"), -200, 2);
    EXPECT_NEAR(test::drive_position(*bench, "drive_z"), -100, 2);
    EXPECT_NE(bench->host().received_text().find("X:0.000 Y:0.000 Z:0.000"), std::string::npos);
    for (const Finding& f : bench->findings()) ADD_FAILURE() << f.source << ": " << f.detail;
}

// The RepRap checksum: XOR of every byte before the '*'.
std::string with_checksum(const std::string& line) {
    unsigned x = 0;
    for (char c : line) x ^= static_cast<unsigned char>(c);
    return line + "*" + std::to_string(x);
}

// Without Marlin's keep-alives ("echo:busy: processing" once a second of waiting).
std::string without_busy(std::string out) {
    const std::string busy = "echo:busy: processing\n";
    for (auto at = out.find(busy); at != std::string::npos; at = out.find(busy)) out.erase(at, busy.size());
    return out;
}

// Sends one line on the raw port and runs until its answer ends with "ok";
// the answer without keep-alives.
std::string send_line(Bench& bench, const std::string& line) {
    SerialLink& port = bench.serial();
    const std::size_t from = port.transmitted_text().size();
    port.send(line + "\n");
    for (int i = 0; i < 300; ++i) {
        bench.run_for(0.01);
        const std::string out = port.transmitted_text().substr(from);
        if (out.size() >= 3 && out.compare(out.size() - 3, 3, "ok\n") == 0) return without_busy(out);
    }
    return port.transmitted_text().substr(from) + "<no ok within 3 s>";
}

TEST(Printer3dJob, ProtocolChecksumsLineNumbersAndErrors) {
    auto bench = test::printer_bench();
    bench->run_for(0.05);  // "start"
    EXPECT_EQ(bench->serial().transmitted_text(), "start\n");
    EXPECT_EQ(send_line(*bench, with_checksum("N1 G21")), "ok\n");
    EXPECT_EQ(send_line(*bench, "N2 G90*99"), "Error:checksum mismatch\nResend: 2\nok\n");
    EXPECT_EQ(send_line(*bench, with_checksum("N3 G90")), "Error:line number is not last line number + 1\nResend: 2\nok\n");
    EXPECT_EQ(send_line(*bench, with_checksum("N2 G90")), "ok\n");
    EXPECT_EQ(send_line(*bench, with_checksum("N100 M110")), "ok\n");
    EXPECT_EQ(send_line(*bench, with_checksum("N101 G91")), "ok\n");
    // printcore (pronsole, Pronterface) starts every print with "N-1 M110" and
    // numbers the job from N0.
    EXPECT_EQ(send_line(*bench, with_checksum("N-1 M110")), "ok\n");
    EXPECT_EQ(send_line(*bench, with_checksum("N0 G91")), "ok\n");
    EXPECT_EQ(send_line(*bench, "G1 X"), "Error:bad number\nok\n");
    EXPECT_EQ(send_line(*bench, "G7"), "Error:unknown G code\nok\n");
    EXPECT_EQ(send_line(*bench, "M999"), "Error:unknown M code\nok\n");
    EXPECT_EQ(send_line(*bench, "G1 X" + std::string(120, '1')), "Error:line too long\nok\n");
    EXPECT_EQ(send_line(*bench, "G1 X20000"), "Error:target out of range\nok\n");
    // Comments, lower case, relative moves (G91 above), a modal feed.
    EXPECT_EQ(send_line(*bench, "g1 x1 f300 ; one millimetre (relative)"), "ok\n");
    EXPECT_EQ(send_line(*bench, "G1 (again) X1"), "ok\n");
    // Inches: 0.1 in = 2.54 mm = 254 BLU.
    EXPECT_EQ(send_line(*bench, "G20"), "ok\n");
    EXPECT_EQ(send_line(*bench, "G1 X0.1"), "ok\n");
    EXPECT_EQ(send_line(*bench, "G21"), "ok\n");
    EXPECT_EQ(send_line(*bench, "M400"), "ok\n");
    EXPECT_EQ(send_line(*bench, "M114"), "X:4.540 Y:0.000 Z:0.000 E:0\nok\n");
    EXPECT_EQ(test::drive_position(*bench, "drive_x"), 454);
    // G92 sets the position without moving.
    EXPECT_EQ(send_line(*bench, "G92 X10"), "ok\n");
    EXPECT_EQ(send_line(*bench, "M114"), "X:10.000 Y:0.000 Z:0.000 E:0\nok\n");
    EXPECT_EQ(test::drive_position(*bench, "drive_x"), 454);
    // An arc needs its centre; the end point must lie on the circle.
    EXPECT_EQ(send_line(*bench, "G2 X1"), "Error:arc needs I/J or R\nok\n");
    EXPECT_EQ(send_line(*bench, "G2 X1 Y1 I5 J0"), "Error:arc end point not on the circle\nok\n");
}

TEST(Printer3dJob, M109WaitsForTheHeaterMcuAndM105ReportsIt) {
    auto bench = test::powered_printer();
    bench->host().add_lines("M109 S60\nM105\n");
    ASSERT_EQ(bench->run_until_idle(60.0), IdleResult::Idle) << bench->host().received_text();
    Mcu& heater = bench->mcu("heater");
    EXPECT_EQ(heater.read_ram_u16("setpoint_c"), 60u);  // sent over TWI
    EXPECT_EQ(heater.read_ram_u8("temp_ok"), 1u);       // M109 returned on TEMP_OK
    const double own_c = static_cast<std::int16_t>(heater.read_ram_u16("temp_x10")) / 10.0;
    EXPECT_LT(std::abs(own_c - 60.0), 5.0);
    // "ok T:<temp> /<setpoint>" in Marlin's form, with the heater's reading.
    const std::string out = bench->host().received_text();
    const auto at = out.rfind("ok T:");
    ASSERT_NE(at, std::string::npos) << out;
    EXPECT_NEAR(std::stod(out.substr(at + 5)), own_c, 1.0);
    EXPECT_NE(out.find("/60.0", at), std::string::npos);
    for (const Finding& f : bench->findings()) ADD_FAILURE() << f.source << ": " << f.detail;
}

// Code 4.11 as printed: F is read per line, so a line without F divides by
// zero (dt_const = 1000000 / 0: on the AVR's division routine all ones, a
// 65.5 ms tick) and a 10 mm move takes minutes; the host hears nothing.
TEST(Printer3dThesisParser, ALineWithoutFNeverFinishes) {
    auto bench = test::powered_printer("printer3d_interp_thesis_parser");
    bench->run_for(0.2);
    const std::string reply = send_line(*bench, "G01 X0.5 Y0");  // 500 BLU at the listing's 1000 BLU/mm
    EXPECT_NE(reply.find("<no ok within 3 s>"), std::string::npos) << reply;
    // With F (mm/s in the listing) the same move is done at once.
    auto fine = test::powered_printer("printer3d_interp_thesis_parser");
    fine->run_for(0.2);
    EXPECT_EQ(send_line(*fine, "G01 X0.5 Y0 F10"), "ok\n");
    EXPECT_EQ(test::drive_position(*fine, "drive_x"), 500);
}

// The thesis' syntax moves Z on its own line (`G01 Z<z> F<feed>`, §4.6) and
// a line with no X/Y travel is an L = 0 DDA: no tick, done. Both are
// answered, and Z takes the listing's 1000 BLU/mm: Z0.2 = 200 full steps.
TEST(Printer3dThesisParser, AZOnlyLineMovesZAloneAndAZeroLengthLineIsAnswered) {
    auto bench = test::powered_printer("printer3d_interp_thesis_parser");
    bench->run_for(0.2);
    EXPECT_EQ(send_line(*bench, "G01 Z0.2 F10"), "ok\n");
    EXPECT_EQ(test::drive_position(*bench, "drive_z"), 200);
    EXPECT_EQ(test::drive_position(*bench, "drive_x"), 0);
    EXPECT_EQ(send_line(*bench, "G01 X0 Y0 F10"), "ok\n");
    EXPECT_EQ(test::drive_position(*bench, "drive_x"), 0);
    EXPECT_EQ(test::drive_position(*bench, "drive_y"), 0);
}

// Code 4.11's G00 never switches the extruder off, so after a G01 (or M03)
// a rapid extrudes too (digest §9.8): SP = 1 step per 8 ticks (§4.7, the
// build's default), 200 ticks of G00 X0.2 at the listing's 1000 BLU/mm.
// The fixed parser's G0 extrudes nothing (Printer3dJob.ExtruderFollows...).
TEST(Printer3dThesisParser, ARapidAfterAFeedMoveExtrudes) {
    auto bench = test::powered_printer("printer3d_interp_thesis_parser");
    Mcu& interp = bench->mcu("interp");
    test::PinLog x(interp, "PA0"), e(interp, "PA3");
    bench->run_for(0.2);
    EXPECT_EQ(send_line(*bench, "G01 X0.1 F10"), "ok\n");
    EXPECT_EQ(send_line(*bench, "G00 X0.2 F10"), "ok\n");
    ASSERT_EQ(x.rises().size(), 300u);  // 100 ticks of G01, 200 of G00
    const Cycle g0_from = x.rises()[100], g0_to = x.rises()[299];
    EXPECT_GE(count_between(e.rises(), g0_from, g0_to), 200u / 8 - 1);
}

// strcpy into char s[50]: a longer line runs over the parser's stack frame
// and its return address; the bench reports the crash with PC and cycle.
TEST(Printer3dThesisParser, ALineLongerThan50BytesCrashesTheInterpolator) {
    auto bench = test::powered_printer("printer3d_interp_thesis_parser");
    bench->run_for(0.2);
    send_line(*bench, "G01 X0.001 Y0.001 F10 " + std::string(60, 'Z'));
    bool crashed = false;
    for (const Finding& f : bench->mcu("interp").findings()) crashed = crashed || f.has_pc;
    EXPECT_TRUE(crashed) << "no crash finding";
    // The fixed parser answers the same line with an error.
    auto fixed = test::powered_printer();
    fixed->run_for(0.3);
    EXPECT_EQ(send_line(*fixed, "G01 X0.001 Y0.001 F10 " + std::string(80, 'Z')), "Error:line too long\nok\n");
}

}  // namespace
}  // namespace avrbench
