#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "trace/GtkwWriter.hpp"
#include "trace/Timeline.hpp"
#include "trace/TraceTestSupport.hpp"

#ifndef AVRBENCH_VERSION
#define AVRBENCH_VERSION "dev"
#endif

namespace avrbench {
namespace {

Timeline three_scopes() {
    Timeline timeline;
    timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, 16000000});
    timeline.add_signal({"mcu", "portb", SignalKind::Bus, 8, 16000000});
    timeline.add_signal({"heater", "temp_degC", SignalKind::Real, 64, 16000000});
    timeline.add_signal({"x_driver", "step", SignalKind::Wire, 1, 16000000});
    timeline.add_signal({"mcu", "flag", SignalKind::Bus, 1, 16000000});  // back in mcu's group
    return timeline;
}

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(GtkwWriter, OneGroupPerScopeWithFormatsPerKind) {
    GtkwOptions options;
    options.analog_extra_rows = 1;
    options.buses = VcdBuses::Vector;
    const std::string text = format_gtkw(three_scopes(), "run.vcd", "run.gtkw", options);
    // Flags (gtkwave TR_* bits): 28 = bin|rjustify, 22 = hex|rjustify,
    // 8028 = analog step|bin|rjustify, 20000 = analog height row,
    // 800200 / 1000200 = group begin / end (with blank).
    const std::string expected =
        "[*] avrbench " AVRBENCH_VERSION " save file: one group per scope\n"
        "[dumpfile] \"run.vcd\"\n"
        "[savefile] \"run.gtkw\"\n"
        "[timestart] 0\n"
        "[treeopen] mcu.\n"
        "[treeopen] heater.\n"
        "[treeopen] x_driver.\n"
        "@800200\n-mcu\n"
        "@28\nmcu.PB5\n"
        "@22\nmcu.portb[7:0]\n"  // gtkwave names an 8-bit vector declared without range this way
        "@28\nmcu.flag\n"        // a 1-bit bus is a plain bit
        "@1000200\n-mcu\n"
        "@800200\n-heater\n"
        "@8028\nheater.temp_degC\n"
        "@20000\n-\n"
        "@1000200\n-heater\n"
        "@800200\n-x_driver\n"
        "@28\nx_driver.step\n"
        "@1000200\n-x_driver\n";
    EXPECT_EQ(text, expected);
    EXPECT_EQ(count(text, "@800200\n"), 3u);   // one group per scope
    EXPECT_EQ(count(text, "@1000200\n"), 3u);
}

// A dump whose buses are bits (the default): each bus is one trace again,
// gtkwave's concatenation "#{name[msb:0]} name[msb] ... name[0]".
TEST(GtkwWriter, BusesWrittenAsBitsAreJoinedIntoOneTrace) {
    const std::string text = format_gtkw(three_scopes(), "run.vcd", "run.gtkw");
    EXPECT_NE(text.find("@22\n#{mcu.portb[7:0]} mcu.portb[7] mcu.portb[6] mcu.portb[5] mcu.portb[4] mcu.portb[3] "
                        "mcu.portb[2] mcu.portb[1] mcu.portb[0]\n"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("@28\nmcu.flag\n"), std::string::npos) << text;  // a 1-bit bus stays one wire
}

// A board's save file opens on what the board file names: nets and labels
// first, then the parts, then each MCU's bytes; its raw pins come last in a
// collapsed group (@c00200), one click away. The window is sized.
TEST(GtkwWriter, BoardNamesComeFirstAndRawPinsLastCollapsed) {
    Timeline timeline;
    const SignalId pd2 = timeline.add_signal({"uno", "PD2", SignalKind::Wire, 1, 16000000});
    timeline.add_signal({"uno", "uart0_tx", SignalKind::Bus, 8, 16000000, true});
    timeline.add_signal({"x", "position_mm", SignalKind::Real, 64, 16000000});
    timeline.add_alias(pd2, "nets", "x_step");
    GtkwOptions options;
    options.buses = VcdBuses::Vector;
    options.analog_extra_rows = 0;
    options.background_scopes = {"uno"};
    options.window_width = 1400;
    options.window_height = 900;
    const std::string text = format_gtkw(timeline, "run.vcd", "");
    const std::string sized = format_gtkw(timeline, "run.vcd", "", options);
    EXPECT_NE(sized.find("[size] 1400 900\n"), std::string::npos) << sized;
    const std::string groups = sized.substr(sized.find("@800200"));
    EXPECT_EQ(groups,
              "@800200\n-nets\n@28\nnets.x_step\n@1000200\n-nets\n"
              "@800200\n-uno\n@820\nuno.uart0_tx[7:0]\n@1000200\n-uno\n"
              "@800200\n-x\n@8028\nx.position_mm\n@1000200\n-x\n"
              "@c00200\n-uno pins\n@28\nuno.PD2\n@1000200\n-uno pins\n");
    EXPECT_EQ(text.find("[size]"), std::string::npos);  // no size asked: gtkwave's default
}

TEST(GtkwWriter, ClosedGroupsAndDefaults) {
    GtkwOptions options;
    options.groups_closed = true;
    const std::string text = format_gtkw(three_scopes(), "/abs/run.vcd", "", options);
    EXPECT_EQ(count(text, "@c00200\n"), 3u);  // TR_CLOSED | TR_GRP_BEGIN | TR_BLANK
    EXPECT_EQ(count(text, "@800200\n"), 0u);
    EXPECT_EQ(count(text, "[savefile]"), 0u);
    EXPECT_EQ(count(text, "@20000\n-\n"), 3u);  // default: 3 extra rows for the one real
    EXPECT_NE(text.find("[dumpfile] \"/abs/run.vcd\"\n"), std::string::npos);
}

TEST(GtkwWriter, WritesFilesDeterministicallyAndReportsErrors) {
    trace_test::ScratchDir dir;
    write_gtkw(three_scopes(), dir.file("a.gtkw"), "a.vcd");
    write_gtkw(three_scopes(), dir.file("b.gtkw"), "a.vcd");
    const std::string a = trace_test::read_text(dir.file("a.gtkw"));
    EXPECT_NE(a.find("[savefile] \"a.gtkw\"\n"), std::string::npos) << a;  // file name only, no directory
    EXPECT_EQ(a.find(dir.path().string()), std::string::npos);
    const std::string b = trace_test::read_text(dir.file("b.gtkw"));
    EXPECT_EQ(a.substr(a.find("[timestart]")), b.substr(b.find("[timestart]")));

    const std::string bad = "/nonexistent-avrbench-dir/x.gtkw";
    try {
        write_gtkw(three_scopes(), bad, "x.vcd");
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
    EXPECT_THROW(format_gtkw(three_scopes(), "a\"b.vcd", ""), std::invalid_argument);
    EXPECT_THROW(format_gtkw(three_scopes(), "a\nb.vcd", ""), std::invalid_argument);
}

}  // namespace
}  // namespace avrbench
