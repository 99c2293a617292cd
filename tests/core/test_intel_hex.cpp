// mcu/IntelHex against records written by hand from Intel's "Hexadecimal
// Object File Format Specification" (rev. A): ':' count(1) address(2) type(1)
// data checksum, the checksum being the two's complement of the byte sum.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "core/Errors.hpp"
#include "mcu/IntelHex.hpp"

namespace avrbench {
namespace {

class IntelHexFile : public ::testing::Test {
protected:
    std::string write(const std::string& text) {
        std::ofstream(path_) << text;
        return path_;
    }
    void TearDown() override { std::filesystem::remove(path_); }
    std::string error_of(const std::string& text) {
        try {
            read_intel_hex(write(text));
        } catch (const BadInput& e) {
            return e.what();
        }
        return "(accepted)";
    }

private:
    std::string path_ = (std::filesystem::temp_directory_path() / ("avrbench-test-ihex-" + std::to_string(::getpid()) + ".hex")).string();
};

// :03 0010 00 AA BB CC: 03+00+10+00+AA+BB+CC = 0x244, checksum 0x100-0x44 = 0xBC.
// :03 0013 00 01 02 03: 03+00+13+00+01+02+03 = 0x1C, checksum 0xE4 (follows on: one chunk).
// :02 0000 04 0001: 02+04+01 = 0x07, checksum 0xF9 (base 0x10000).
// :02 0000 02 1000: 02+02+10 = 0x14, checksum 0xEC (base 0x1000 << 4 = 0x10000).
// :01 0000 00 5A: 01+5A = 0x5B, checksum 0xA5.
TEST_F(IntelHexFile, MergesContiguousRecordsAndAppliesAddressRecords) {
    const auto chunks = read_intel_hex(write(":03001000AABBCCBC\n:03001300010203E4\r\n"
                                             ":020000040001F9\n:010000005AA5\n"
                                             ":00000001FF\n"));
    ASSERT_EQ(chunks.size(), 2u);
    EXPECT_EQ(chunks[0].address, 0x0010u);
    EXPECT_EQ(chunks[0].bytes, (std::vector<std::uint8_t>{0xAA, 0xBB, 0xCC, 0x01, 0x02, 0x03}));
    EXPECT_EQ(chunks[1].address, 0x10000u);
    EXPECT_EQ(chunks[1].bytes, (std::vector<std::uint8_t>{0x5A}));

    const auto segment = read_intel_hex(write(":020000021000EC\n:010000005AA5\n:00000001FF\n"));
    ASSERT_EQ(segment.size(), 1u);
    EXPECT_EQ(segment[0].address, 0x10000u);
}

TEST_F(IntelHexFile, NamesTheLineAndTheProblem) {
    EXPECT_NE(error_of(":03001000AABBCCBC\n:03001300010203E5\n:00000001FF\n").find(":2: checksum does not match"), std::string::npos);
    EXPECT_NE(error_of(":03001000AABBCCBC\n").find("no end-of-file record"), std::string::npos);
    EXPECT_NE(error_of("hello\n").find(":1: not an Intel HEX record"), std::string::npos);
    EXPECT_NE(error_of(":0300100GAABBCCBC\n").find(":1: '0G' is not a hex byte"), std::string::npos);
    EXPECT_NE(error_of(":04001000AABBCCBC\n").find(":1: byte count 4"), std::string::npos);
    EXPECT_NE(error_of(":010010005A95\n:010010005A95\n:00000001FF\n").find(":2: data at 0x00010 was already given"), std::string::npos)
        << error_of(":010010005A95\n:010010005A95\n:00000001FF\n");
    EXPECT_NE(error_of(":00000001FF\n:010000005AA5\n").find(":2: data after the end-of-file record"), std::string::npos);
    EXPECT_NE(error_of(":0000000AF6\n:00000001FF\n").find(":1: unknown record type 10"), std::string::npos);
    EXPECT_NE(error_of("").find("no end-of-file record"), std::string::npos);
    try {
        read_intel_hex("/nonexistent/boot.hex");
        FAIL();
    } catch (const BadInput& e) {
        EXPECT_EQ(std::string(e.what()), "Intel HEX file: /nonexistent/boot.hex: no such file");
    }
}

}  // namespace
}  // namespace avrbench
