// What a job file may contain: text with any line ends; anything else is one
// clear line naming file, line and byte.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/Errors.hpp"
#include "stimulus/UartHost.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

std::string error_of(const std::string& bytes) {
    try {
        checked_gcode_text(bytes, "job.gcode");
    } catch (const BadInput& e) {
        return e.what();
    }
    return "(accepted)";
}

using namespace std::string_literals;

TEST(GcodeInput, BytesThatAreNotTextAreRejectedWithFileLineAndByte) {
    EXPECT_EQ(error_of("G1 X1\nG1 X\0" "2\n"s), "job.gcode:2: control byte 0x00 at column 5 is not G-code text");
    EXPECT_EQ(error_of("G1 X1\x1b[0m\n"), "job.gcode:1: control byte 0x1b at column 6 is not G-code text");
    EXPECT_EQ(error_of("\xff\xfeG\0" "1\0"s), "job.gcode:1: UTF-16 text (byte-order mark 0xff 0xfe); save the job as ASCII or UTF-8");
    EXPECT_EQ(error_of("G1 X1 ; caf\xe9\n"), "job.gcode:1: byte 0xe9 at column 12 is not UTF-8 text");  // Latin-1
    // Accepted: UTF-8 in comments, tabs, every kind of line end.
    EXPECT_EQ(error_of("G1 X1 ; caf\xc3\xa9\n\tG1 X2\r\nG1 X3\rG1 X4"), "(accepted)");
}

TEST(GcodeInput, CrOnlyCrLfAndLfAllEndLinesAndAUtf8BomIsSkipped) {
    const std::string text = "\xef\xbb\xbfG1 X1\rG1 X2\r\nG1 X3\nG1 X4\r";
    const auto lines = parse_gcode(checked_gcode_text(text, "job.gcode"), "job.gcode");
    ASSERT_EQ(lines.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(lines[i].text, "G1 X" + std::to_string(i + 1));
        EXPECT_EQ(lines[i].number, i + 1);
    }
}

TEST(GcodeInput, TheCliSaysItInOneLineWithExitCode2) {
    const auto dir = test::scratch_dir("gcode-bytes");
    const auto job = dir / "nul.gcode";
    std::ofstream(job, std::ios::binary) << "G21\nG1 X1\0" "0\n"s;
    const auto r = test::run_command(std::string(::avrbench::test::cli()) + " run -q --board " +
                                         test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml") + " " +
                                         test::firmware("stepdir_test") + " --gcode " + job.string(), dir, 30);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, "avrbench: error: " + job.string() + ":2: control byte 0x00 at column 6 is not G-code text\n");
}

}  // namespace
}  // namespace avrbench
