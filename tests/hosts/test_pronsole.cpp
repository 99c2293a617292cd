// A real RepRap host on the emulated printer: Debian's pronsole (printrun)
// connects to seed 001's five-MCU board through `avrbench run --pty`, loads
// a short job and prints it, scripted through its -e options. The bench runs
// at --pace realtime (pronsole's timing is wall-clock). Expected positions
// come from the job: each carriage homes onto its switch 0.5 mm from the stop,
// then X2 Y2 Z0.2 mm from there; the carriage follows the rotor, a step
// (0.01 mm) behind at most. Wall-clock guards: pronsole 60 s, the whole 120 s.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

// "axis x     501 full steps of the rotor, at 2.4950 mm" -> 2.495; -1 if absent.
double axis_mm(const std::string& summary, const std::string& axis) {
    const auto line = summary.find("  axis " + axis + " ");
    if (line == std::string::npos) return -1;
    const auto at = summary.find(", at ", line);
    if (at == std::string::npos) return -1;
    return std::stod(summary.substr(at + 5));
}

TEST(Pronsole, PrintsAJobOnTheEmulatedPrinterThroughThePty) {
    const auto dir = test::scratch_dir("pronsole");
    {
        std::ofstream job(dir / "job.gcode");
        job << "G28\nG1 X2 Y2 F500\nG1 Z0.2\nM105\nM400\nM114\n";
    }
    const std::string fw = std::string(::avrbench::test::firmware_dir()) + "/";
    const std::string bench = std::string(::avrbench::test::cli()) + " run " + fw + "printer3d_interp.elf --board " +
                              test::source_path("bench/boards/printer3d-seed001.yaml") + " --firmware drive_x=" + fw +
                              "printer3d_drive.elf --firmware drive_y=" + fw + "printer3d_drive.elf --firmware drive_z=" +
                              fw + "printer3d_drive.elf --firmware drive_e=" + fw +
                              "printer3d_drive.elf --firmware heater=" + fw +
                              "printer3d_heater.elf --pty host --pty-link ttyP3 --uart-out host=firmware.txt --pace realtime --for 8s";
    // pronsole's "shell" runs a Python line in pronsole itself (its help:
    // "Executes a python command"): here, wait until the print is done.
    const std::string pronsole =
        "timeout 60 pronsole -e 'connect ttyP3 115200' -e block_until_online -e 'load job.gcode' -e print"
        " -e \"shell import time; exec('while self.p.printing: time.sleep(0.2)')\" -e exit";
    const auto r = test::run_command("cd " + test::quoted(dir.string()) + " || exit 1; " + bench + " > bench.out 2>&1 & b=$!; i=0; while [ ! -e ttyP3 ] && [ $i -lt 100 ]; do "
                                     "sleep 0.1; i=$((i+1)); done; HOME=$PWD " +
                                     pronsole + " > pronsole.out 2>&1; echo $? > pronsole.rc; wait $b",
                                     dir, 120);
    ASSERT_EQ(r.exit_code, 0) << r.err << test::slurp(dir / "bench.out");
    EXPECT_EQ(test::slurp(dir / "pronsole.rc"), "0\n") << test::slurp(dir / "pronsole.out");
    const std::string summary = test::slurp(dir / "bench.out");
    EXPECT_NEAR(axis_mm(summary, "x"), 2.5, 0.02) << summary;
    EXPECT_NEAR(axis_mm(summary, "y"), 2.5, 0.02) << summary;
    EXPECT_NEAR(axis_mm(summary, "z"), 0.7, 0.02) << summary;
    EXPECT_NE(summary.find("  findings   0"), std::string::npos) << summary;
    // printcore numbered the job (N-1 M110, then N0..): no line was refused,
    // and M114 reported the job's position.
    const std::string firmware_out = test::slurp(dir / "firmware.txt");
    EXPECT_EQ(firmware_out.find("Error:"), std::string::npos) << firmware_out;
    EXPECT_NE(firmware_out.find("X:2.000 Y:2.000 Z:0.200"), std::string::npos) << firmware_out;
}

}  // namespace
}  // namespace avrbench
