#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "trace/TraceTestSupport.hpp"
#include "trace/VcdReader.hpp"

namespace avrbench {
namespace {

// A dump in the style other simulators write: $date, multi-line sections, a
// two-token timescale, nested scopes, an explicit bit range, an alias (two
// variables on one identifier), $dumpvars, comments between changes.
const char* const kForeignDump = R"($date
    Mon Jan  1 00:00:00 2024
$end
$version Icarus Verilog $end
$timescale 10 ns $end
$scope module top $end
$var wire 1 ! clk $end
$scope module cpu $end
$var reg 8 " data [7:0] $end
$var wire 1 ! clk_alias $end
$var real 64 # vcc $end
$upscope $end
$upscope $end
$enddefinitions $end
#0
$dumpvars
0!
bxxxxxxxx "
r3.3 #
$end
#5
1!
b101 "
$comment a comment between changes $end
#10
0!
R4.75 #
#12
)";

TEST(VcdReader, ReadsHeaderScopesVariablesAndChanges) {
    const VcdDump dump = parse_vcd(kForeignDump);
    EXPECT_EQ(dump.version, "Icarus Verilog");
    EXPECT_EQ(dump.timescale, "10ns");
    EXPECT_EQ(dump.timescale_fs, 10000000u);  // 10 ns = 10 * 10^6 fs
    EXPECT_EQ(dump.scopes, (std::vector<std::string>{"top", "top.cpu"}));
    ASSERT_EQ(dump.variables.size(), 4u);

    const VcdVariable& clk = dump.at("top.clk");
    EXPECT_EQ(clk.type, "wire");
    EXPECT_EQ(clk.id, "!");
    ASSERT_EQ(clk.changes.size(), 3u);
    EXPECT_EQ(clk.changes[1].time, 5u);
    EXPECT_EQ(clk.changes[1].value, "1");

    // The alias on '!' sees the same changes.
    EXPECT_EQ(dump.at("top.cpu.clk_alias").changes.size(), 3u);

    const VcdVariable& data = dump.at("top.cpu.data[7:0]");
    EXPECT_EQ(data.type, "reg");
    EXPECT_EQ(data.width, 8u);
    EXPECT_EQ(data.scope, "top.cpu");
    ASSERT_EQ(data.changes.size(), 2u);
    EXPECT_EQ(data.changes[0].value, "xxxxxxxx");
    EXPECT_EQ(data.changes[1].value, "101");  // as written, not zero-extended

    const VcdVariable& vcc = dump.at("top.cpu.vcc");
    ASSERT_EQ(vcc.changes.size(), 2u);
    EXPECT_EQ(vcc.changes[1].time, 10u);
    EXPECT_EQ(vcc.changes[1].value, "4.75");

    EXPECT_EQ(dump.end_time, 12u);  // the trailing timestamp counts
    EXPECT_EQ(dump.find("top.nope"), nullptr);
    EXPECT_THROW((void)dump.at("top.nope"), std::out_of_range);
}

// Parses `text` expecting an error whose message names line `line` and contains
// `what`. Errors at the end of the file name the last line with text.
void expect_error(const std::string& text, int line, const std::string& what) {
    try {
        parse_vcd(text, "bad.vcd");
        ADD_FAILURE() << "accepted:\n" << text;
    } catch (const std::runtime_error& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind("bad.vcd:" + std::to_string(line) + ": ", 0), 0u) << message;
        EXPECT_NE(message.find(what), std::string::npos) << message;
    }
}

const std::string kHeader =  // 5 lines
    "$timescale 1ns $end\n"
    "$scope module m $end\n"
    "$var wire 1 ! a $end\n"
    "$var wire 4 \" b $end\n"
    "$upscope $end\n";

TEST(VcdReader, RejectsMalformedInputNamingTheLine) {
    expect_error(kHeader + "$enddefinitions $end\n#0\n1?\n", 8, "undeclared identifier '?'");
    expect_error(kHeader + "$enddefinitions $end\n#10\n1!\n#9\n", 9, "time goes backwards");
    expect_error(kHeader + "$enddefinitions $end\n#0\nb10101 \"\n", 8, "5-bit value for 4-bit variable 'm.b'");
    expect_error(kHeader + "$enddefinitions $end\n#0\n1\"\n", 8, "scalar value for 4-bit variable");
    expect_error(kHeader + "$enddefinitions $end\n#0\nr1.5 !\n", 8, "real value for non-real variable 'm.a'");
    expect_error(kHeader + "$enddefinitions $end\n#0\nb012 \"\n", 8, "bad vector value");
    expect_error(kHeader + "$enddefinitions $end\n#0\nq!\n", 8, "unexpected 'q!'");
    expect_error(kHeader + "$enddefinitions $end\n#zz\n", 7, "bad timestamp 'zz'");
    expect_error(kHeader + "$enddefinitions $end\n$dumpvars\n1!\n", 8, "unterminated $dumpvars starting at line 7");
    expect_error(kHeader + "$enddefinitions $end\n$end\n", 7, "$end without an open section");
    expect_error(kHeader + "$bogus $end\n", 6, "unexpected '$bogus' in the header");
    expect_error(kHeader, 5, "unexpected end of file before $enddefinitions");
    expect_error("$comment never\nclosed\n\n", 2, "unterminated $comment starting at line 1");
    expect_error("$timescale 1 ks $end\n", 1, "bad $timescale '1 ks'");
    expect_error("$timescale 3ns $end\n", 1, "bad $timescale");
    expect_error("$scope module m $end\n$var wire 0 ! a $end\n", 2, "$var size must be at least 1");
    expect_error("$scope module m $end\n$var wyre 1 ! a $end\n", 2, "unknown $var type 'wyre'");
    expect_error("$scope module m $end\n$enddefinitions $end\n", 2, "$scope 'm' still open");
    expect_error("$upscope $end\n", 1, "$upscope without an open $scope");
}

TEST(VcdReader, ReadsFilesAndNamesUnreadablePaths) {
    trace_test::ScratchDir dir;
    trace_test::write_text(dir.file("a.vcd"), kForeignDump);
    EXPECT_EQ(read_vcd(dir.file("a.vcd")).variables.size(), 4u);
    const std::string missing = dir.file("missing.vcd");
    try {
        read_vcd(missing);
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    }
    // Errors in a file name the file.
    trace_test::write_text(dir.file("bad.vcd"), "$enddefinitions $end\n#0\n1!\n");
    try {
        read_vcd(dir.file("bad.vcd"));
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), dir.file("bad.vcd") + ":3: value change for undeclared identifier '!'");
    }
}

}  // namespace
}  // namespace avrbench
