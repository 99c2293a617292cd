// avrdude (Debian's, a real process) flashes an application through the
// boot loader of an emulated Arduino over `avrbench run --pty`, as the
// Arduino IDE uploads: optiboot on the UNO (-c arduino), the stk500v2 boot
// loader on the Mega 2560 (-c wiring, with -D as the IDE's platform.txt
// passes: that boot loader answers the chip-erase command with "failed").
// The run starts with blink_timer1 in the application section (silent on the
// serial port); the new application, uart_echo, sends "avrbench uart_echo"
// as soon as it runs. Expected: avrdude writes and verifies the image (its
// verify reads the emulated flash back through the boot loader), the
// banner follows in the firmware's serial output, the summary says the
// application section no longer holds the ELF, and no finding.
// Wall-clock guards: avrdude 60 s, the whole 90 s.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "mcu/IntelHex.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

struct Upload {
    const char* name;
    const char* board;
    const char* initial;  // ELF in the application section at power-on
    const char* image;    // what avrdude writes (.hex next to the ELF)
    const char* avrdude;  // programmer and part
};

const Upload kUno{"UnoOptiboot", "arduino-uno-optiboot", "blink_timer1", "uart_echo", "-c arduino -p m328p"};
const Upload kMega{"MegaStk500v2", "arduino-mega2560", "blink_timer1_m2560", "uart_echo_m2560", "-c wiring -p m2560 -D"};

class Avrdude : public ::testing::TestWithParam<const Upload*> {};

TEST_P(Avrdude, FlashesAndVerifiesThroughTheBootLoaderAndTheNewApplicationRuns) {
    const Upload& u = *GetParam();
    const auto dir = test::scratch_dir(std::string("avrdude-") + u.name);
    const std::string fw = std::string(::avrbench::test::firmware_dir()) + "/";
    const std::string hex = fw + u.image + ".hex";
    std::size_t image_bytes = 0;
    for (const auto& chunk : read_intel_hex(hex)) image_bytes += chunk.bytes.size();

    const std::string bench = std::string(::avrbench::test::cli()) + " run " + fw + u.initial + ".elf --board " + u.board +
                              " --pty host --pty-link tty --reset-on-open --pace realtime"
                              " --uart-out host=firmware.txt --vcd run.vcd --for 6s";
    const std::string avrdude = std::string("timeout 60 avrdude ") + u.avrdude + " -P tty -b 115200 -U flash:w:" + hex + ":i";
    const auto r = test::run_command("cd " + test::quoted(dir.string()) + " || exit 1; " + bench +
                                         " > bench.out 2>&1 & b=$!; i=0; while [ ! -e tty ] && [ $i -lt 100 ]; do "
                                         "sleep 0.1; i=$((i+1)); done; " +
                                         avrdude + " > avrdude.out 2>&1; echo $? > avrdude.rc; wait $b",
                                     dir, 90);
    ASSERT_EQ(r.exit_code, 0) << r.err << test::slurp(dir / "bench.out");
    const std::string log = test::slurp(dir / "avrdude.out");
    EXPECT_EQ(test::slurp(dir / "avrdude.rc"), "0\n") << log;
    EXPECT_NE(log.find(std::to_string(image_bytes) + " bytes of flash written"), std::string::npos) << log;
    EXPECT_NE(log.find(std::to_string(image_bytes) + " bytes of flash verified"), std::string::npos) << log;

    const std::string summary = test::slurp(dir / "bench.out");
    EXPECT_NE(summary.find("the application section now differs from the ELF"), std::string::npos) << summary;
    EXPECT_NE(summary.find("  findings   0"), std::string::npos) << summary;
    const std::string serial = test::slurp(dir / "firmware.txt");
    EXPECT_NE(serial.find("avrbench uart_echo\r\n"), std::string::npos) << "the new application did not run";
}

// The UNO's lock byte 0x0F (boards.txt; BLB12..11 = 00, "SPM is not allowed
// to write to the Boot Loader section") keeps a hex that reaches into
// optiboot's section from overwriting it: optiboot's SPM page write there
// does nothing and avrdude's verify finds optiboot's own bytes at 0x7F80.
TEST(AvrdudeLockBits, CannotOverwriteTheBootLoader) {
    const auto dir = test::scratch_dir("avrdude-lock");
    {
        // 8 records of 16 x 0x55 at 0x7F80..0x7FFF; checksum = two's complement of the byte sum.
        std::ofstream hex(dir / "over.hex");
        for (unsigned a = 0x7F80; a < 0x8000; a += 16) {
            unsigned sum = 16 + (a >> 8) + (a & 0xFF) + 16 * 0x55;
            char line[64];
            std::snprintf(line, sizeof line, ":10%04X00", a);
            hex << line;
            for (int i = 0; i < 16; ++i) hex << "55";
            std::snprintf(line, sizeof line, "%02X\n", (0x100 - (sum & 0xFF)) & 0xFF);
            hex << line;
        }
        hex << ":00000001FF\n";
    }
    const std::string bench = std::string(::avrbench::test::cli()) + " run " + test::firmware("blink_timer1") +
                              " --board arduino-uno-optiboot --pty host --pty-link tty --reset-on-open --pace realtime --for 4s";
    const auto r = test::run_command("cd " + test::quoted(dir.string()) + " || exit 1; " + bench +
                                         " > bench.out 2>&1 & b=$!; i=0; while [ ! -e tty ] && [ $i -lt 100 ]; do "
                                         "sleep 0.1; i=$((i+1)); done; timeout 60 avrdude -c arduino -p m328p -P tty "
                                         "-b 115200 -D -U flash:w:over.hex:i > avrdude.out 2>&1; echo $? > avrdude.rc; wait $b",
                                     dir, 90);
    ASSERT_EQ(r.exit_code, 0) << r.err << test::slurp(dir / "bench.out");
    const std::string log = test::slurp(dir / "avrdude.out");
    EXPECT_NE(test::slurp(dir / "avrdude.rc"), "0\n") << log;
    EXPECT_NE(log.find("128 bytes of flash written"), std::string::npos) << log;
    EXPECT_NE(log.find("!= input 0x55 at addr 0x7f80"), std::string::npos) << log;
}

std::string upload_name(const ::testing::TestParamInfo<const Upload*>& param_info) { return param_info.param->name; }

INSTANTIATE_TEST_SUITE_P(Boards, Avrdude, ::testing::Values(&kUno, &kMega), upload_name);

}  // namespace
}  // namespace avrbench
