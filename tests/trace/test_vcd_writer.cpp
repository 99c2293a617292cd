#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include "trace/Timeline.hpp"
#include "trace/TraceTestSupport.hpp"
#include "trace/VcdReader.hpp"
#include "trace/VcdWriter.hpp"

#ifndef AVRBENCH_VERSION
#define AVRBENCH_VERSION "dev"
#endif

namespace avrbench {
namespace vcd_writer_test {

using trace_test::ScratchDir;

constexpr std::uint32_t k16MHz = 16000000;
constexpr std::uint32_t k20MHz = 20000000;

// Buses as one VCD vector each (the format tests below); the default, one
// wire per bit, has tests of its own (BusesAsBits*).
VcdOptions vector_buses() {
    VcdOptions options;
    options.buses = VcdBuses::Vector;
    return options;
}

// The part of a dump after its header.
std::string body_of(const std::string& vcd) {
    const std::string marker = "$enddefinitions $end\n";
    const auto at = vcd.find(marker);
    return at == std::string::npos ? std::string("<no $enddefinitions>") : vcd.substr(at + marker.size());
}

TEST(VcdWriter, SmallDumpMatchesHandWrittenText) {
    Timeline timeline;
    const SignalId pb5 = timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, k16MHz});
    const SignalId portb = timeline.add_signal({"mcu", "portb", SignalKind::Bus, 8, k16MHz});
    const SignalId temp = timeline.add_signal({"heater", "temp_degC", SignalKind::Real, 64, k20MHz});
    timeline.add_signal({"mcu", "PB4", SignalKind::Wire, 1, k16MHz});  // never recorded: x
    timeline.record(pb5, 0, 0);
    timeline.record_real(temp, 0, 21.5);
    timeline.record(pb5, 16000, 1);
    timeline.record(portb, 16000, 0x20);
    timeline.record(pb5, 16000, 1);  // repeats the value: dropped
    timeline.record_real(temp, 40000, 25.25);
    timeline.record(pb5, 32000, 0);

    VcdResult result;
    const std::string vcd = format_vcd(timeline, vector_buses(), &result);
    // Identifiers by registration order: PB5 '!', portb '"', temp_degC '#', PB4 '$'.
    // 16 MHz and 20 MHz -> 100ps; 16000 cycles at 16 MHz = 1 ms = 10^7 units;
    // 32000 at 16 MHz and 40000 at 20 MHz are both 2 ms = 2 * 10^7 units, written
    // in record order (temp first). PB4 is in scope mcu although registered after heater.
    const std::string expected =
        "$version avrbench " AVRBENCH_VERSION " $end\n"
        "$comment cycle times: 16000000 Hz: 625 x 100ps per cycle, exact; "
        "20000000 Hz: 500 x 100ps per cycle, exact; $end\n"
        "$timescale 100ps $end\n"
        "$scope module mcu $end\n"
        "$var wire 1 ! PB5 $end\n"
        "$var wire 8 \" portb $end\n"
        "$var wire 1 $ PB4 $end\n"
        "$upscope $end\n"
        "$scope module heater $end\n"
        "$var real 64 # temp_degC $end\n"
        "$upscope $end\n"
        "$enddefinitions $end\n"
        "#0\n"
        "$dumpvars\n"
        "0!\n"
        "bz \"\n"  // a bus with nothing on it yet
        "r21.5 #\n"
        "x$\n"
        "$end\n"
        "#10000000\n"
        "1!\n"
        "b00100000 \"\n"
        "#20000000\n"
        "r25.25 #\n"
        "0!\n";
    EXPECT_EQ(vcd, expected);
    EXPECT_EQ(result.timescale, "100ps");
    EXPECT_TRUE(result.exact);
    EXPECT_EQ(result.value_changes, 4u);  // 1!, b00100000, r25.25, 0!
    EXPECT_EQ(result.end_time, 20000000u);
}

// The default: a bus is one 1-bit wire per bit, "name[i]", MSB declared
// first, so readers that take only scalars (libsigrok 0.5's VCD input, and
// with it PulseView and sigrok-cli) read the whole dump; only bits that
// change are written. An alias (a net's name) has codes of its own that
// repeat the target's changes: libsigrok keeps one signal per code and would
// leave a second name of the same code empty.
TEST(VcdWriter, BusesAsBitsAreOneWirePerBitWithOnlyChangedBitsWritten) {
    Timeline timeline;
    const SignalId pin = timeline.add_signal({"mcu", "PD1", SignalKind::Wire, 1, k16MHz});
    const SignalId tx = timeline.add_signal({"mcu", "tx", SignalKind::Bus, 3, k16MHz});
    timeline.add_alias(tx, "nets", "link");
    timeline.record(pin, 0, 1);
    timeline.record(tx, 1, 0b101);
    timeline.record(tx, 2, 0b100);  // only bit 0 changes
    const std::string vcd = format_vcd(timeline);
    // Codes: PD1 '!', tx bits 0, 1, 2 '"', '#', '$'; link's bits 0, 1, 2 '%', '&', '\''.
    const std::string expected_header_vars =
        "$scope module mcu $end\n"
        "$var wire 1 ! PD1 $end\n"
        "$var wire 1 $ tx[2] $end\n"
        "$var wire 1 # tx[1] $end\n"
        "$var wire 1 \" tx[0] $end\n"
        "$upscope $end\n"
        "$scope module nets $end\n"
        "$var wire 1 ' link[2] $end\n"
        "$var wire 1 & link[1] $end\n"
        "$var wire 1 % link[0] $end\n"
        "$upscope $end\n";
    EXPECT_NE(vcd.find(expected_header_vars), std::string::npos) << vcd;
    EXPECT_EQ(body_of(vcd),
              "#0\n$dumpvars\n1!\nz$\nz#\nz\"\nz'\nz&\nz%\n$end\n"
              "#625\n1$\n0#\n1\"\n1'\n0&\n1%\n"
              "#1250\n0\"\n0%\n");
    const VcdDump dump = parse_vcd(vcd);
    EXPECT_EQ(dump.at("mcu.tx[2]").width, 1u);
    EXPECT_EQ(dump.at("nets.link[0]").changes.size(), dump.at("mcu.tx[0]").changes.size());

    // Shared codes on request: the alias declares the target's.
    VcdOptions shared;
    shared.alias_codes = false;
    const VcdDump compact = parse_vcd(format_vcd(timeline, shared));
    EXPECT_EQ(compact.at("nets.link[0]").id, compact.at("mcu.tx[0]").id);
}

TEST(VcdWriter, TimestampsAreExactCycleTimesAt16And20MHz) {
    Timeline timeline;
    const SignalId a = timeline.add_signal({"mcu16", "a", SignalKind::Wire, 1, k16MHz});
    timeline.record(a, 16000, 1);      // 1 ms = 10,000,000 x 100ps
    timeline.record(a, 16000001, 0);   // 1 s + 62.5 ns = 10,000,000,000 + 625
    const std::string only16 = body_of(format_vcd(timeline));
    EXPECT_EQ(only16, "#0\n$dumpvars\nx!\n$end\n#10000000\n1!\n#10000000625\n0!\n");

    Timeline twenty;
    const SignalId b = twenty.add_signal({"mcu20", "b", SignalKind::Wire, 1, k20MHz});
    twenty.record(b, 20000, 1);  // 1 ms at 20 MHz alone: 10ns unit -> 100,000
    twenty.record(b, 3, 0);      // recorded late on purpose: 150 ns = 15 units, sorts first
    VcdResult result;
    const std::string vcd20 = format_vcd(twenty, {}, &result);
    EXPECT_EQ(result.timescale, "10ns");
    EXPECT_EQ(body_of(vcd20), "#0\n$dumpvars\nx!\n$end\n#15\n0!\n#100000\n1!\n");
}

TEST(VcdWriter, MixedClockDomainsAreMergedInTimeOrder) {
    Timeline timeline;
    const SignalId a = timeline.add_signal({"mcu", "a", SignalKind::Wire, 1, k16MHz});
    const SignalId b = timeline.add_signal({"slave", "b", SignalKind::Wire, 1, k20MHz});
    // Times in 100ps: 16 MHz cycle c -> 625c, 20 MHz cycle c -> 500c.
    timeline.record(a, 8, 0);   // 5000 (record index 0)
    timeline.record(b, 9, 1);   // 4500
    timeline.record(b, 10, 0);  // 5000 (record index 2: after a at the same time)
    timeline.record(a, 4, 1);   // 2500, recorded last
    EXPECT_EQ(body_of(format_vcd(timeline)),
              "#0\n$dumpvars\nx!\nx\"\n$end\n"
              "#2500\n1!\n"
              "#4500\n1\"\n"
              "#5000\n0!\n0\"\n");
}

TEST(VcdWriter, DropsEventsThatDoNotChangeTheValueAndLastValueAtATimeWins) {
    Timeline timeline;
    const SignalId pin = timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, k16MHz});
    const std::uint64_t values[] = {1, 1, 0, 0, 1};
    for (Cycle cycle = 1; cycle <= 5; ++cycle) timeline.record(pin, cycle, values[cycle - 1]);
    timeline.record(pin, 10, 0);  // 0 then 1 at one time: ends where it was (1), no timestamp at all
    timeline.record(pin, 10, 1);
    timeline.record(pin, 12, 7);  // any nonzero is 1: unchanged
    VcdResult result;
    const std::string body = body_of(format_vcd(timeline, {}, &result));
    // Changes at cycles 1, 3, 5 -> 625, 1875, 3125 x 100ps.
    EXPECT_EQ(body, "#0\n$dumpvars\nx!\n$end\n#625\n1!\n#1875\n0!\n#3125\n1!\n");
    EXPECT_EQ(result.value_changes, 3u);
    EXPECT_EQ(result.end_time, 3125u);
}

TEST(VcdWriter, BusAndRealFormatting) {
    Timeline timeline;
    const SignalId byte = timeline.add_signal({"m", "byte", SignalKind::Bus, 8, k16MHz});
    const SignalId wide = timeline.add_signal({"m", "wide", SignalKind::Bus, 64, k16MHz});
    const SignalId bit = timeline.add_signal({"m", "bit", SignalKind::Bus, 1, k16MHz});
    const SignalId real = timeline.add_signal({"m", "real", SignalKind::Real, 64, k16MHz});
    timeline.record(byte, 1, 0x1FF);  // masked to 8 bits
    timeline.record(wide, 1, std::numeric_limits<std::uint64_t>::max());
    timeline.record(bit, 1, 1);  // a 1-bit bus is a scalar
    timeline.record(byte, 2, 0x05);
    const double reals[] = {0.1, 1e-7, -0.0, 1.0 / 3.0, 1e300, 100.0, std::numeric_limits<double>::infinity()};
    Cycle cycle = 3;
    for (const double value : reals) timeline.record_real(real, cycle++, value);
    const std::string body = body_of(format_vcd(timeline, vector_buses()));
    const std::string ones64(64, '1');
    EXPECT_EQ(body,
              "#0\n$dumpvars\nbz !\nbz \"\nz#\nr0 $\n$end\n"
              "#625\nb11111111 !\nb" + ones64 + " \"\n1#\n"
              "#1250\nb00000101 !\n"
              // shortest round-trip text (std::to_chars): -0 differs from 0 in its bits, so it is written
              "#1875\nr0.1 $\n#2500\nr1e-07 $\n#3125\nr-0 $\n#3750\nr0.3333333333333333 $\n"
              "#4375\nr1e+300 $\n#5000\nr100 $\n#5625\nrinf $\n");
    const VcdDump dump = parse_vcd(format_vcd(timeline, vector_buses()));
    const auto& changes = dump.at("m.real").changes;
    ASSERT_EQ(changes.size(), 8u);  // r0 + 7 values
    EXPECT_EQ(std::stod(changes[4].value), 1.0 / 3.0);  // reads back bit-exact
}

TEST(VcdWriter, InitialValuesComeFromTimeZeroEventsElseUnknown) {
    Timeline timeline;
    const SignalId wire = timeline.add_signal({"m", "wire", SignalKind::Wire, 1, k16MHz});
    const SignalId bus = timeline.add_signal({"m", "bus", SignalKind::Bus, 4, k16MHz});
    const SignalId real = timeline.add_signal({"m", "real", SignalKind::Real, 64, k16MHz});
    timeline.record(wire, 0, 1);
    timeline.record(wire, 0, 0);  // last value at time 0 wins
    timeline.record(bus, 0, 0xA);
    timeline.record_real(real, 5, 0.0);  // r0 already shown: nothing to write
    timeline.record(bus, 1, 0xA);        // unchanged
    VcdResult result;
    EXPECT_EQ(body_of(format_vcd(timeline, vector_buses(), &result)), "#0\n$dumpvars\n0!\nb1010 \"\nr0 #\n$end\n");
    EXPECT_EQ(result.value_changes, 0u);
    EXPECT_EQ(result.end_time, 0u);
}

TEST(VcdWriter, EndCycleExtendsTheDumpToTheWholeRun) {
    Timeline timeline;
    const SignalId pin = timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, k16MHz});
    timeline.record(pin, 16000, 1);
    VcdOptions options;
    options.end_cycle = 160000;  // 10 ms at 16 MHz = 100,000,000 x 100ps
    VcdResult result;
    std::string vcd = format_vcd(timeline, options, &result);
    EXPECT_EQ(body_of(vcd), "#0\n$dumpvars\nx!\n$end\n#10000000\n1!\n#100000000\n");
    EXPECT_EQ(result.end_time, 100000000u);
    EXPECT_EQ(parse_vcd(vcd).end_time, 100000000u);

    options.end_cycle = 8000;  // before the last change: nothing to add
    EXPECT_EQ(body_of(format_vcd(timeline, options)), "#0\n$dumpvars\nx!\n$end\n#10000000\n1!\n");

    // The end clock takes part in choosing the unit: 20 MHz alone would be 10ns.
    Timeline twenty;
    twenty.add_signal({"m", "b", SignalKind::Wire, 1, k20MHz});
    options.end_cycle = 1;
    options.end_clock_hz = k16MHz;
    EXPECT_EQ(body_of(format_vcd(twenty, options, &result)), "#0\n$dumpvars\nx!\n$end\n#625\n");
    EXPECT_EQ(result.timescale, "100ps");
}

TEST(VcdWriter, ClockWithoutExactUnitIsFlaggedAndRounded) {
    Timeline timeline;
    const SignalId pin = timeline.add_signal({"uno", "PD1", SignalKind::Wire, 1, 14745600});
    timeline.record(pin, 3, 1);  // 3 / 14.7456 MHz = 203,450,520.83 fs -> 203450521
    VcdResult result;
    const std::string vcd = format_vcd(timeline, {}, &result);
    EXPECT_FALSE(result.exact);
    EXPECT_EQ(result.timescale, "1fs");
    EXPECT_NE(vcd.find("14745600 Hz: rounded to the nearest 1fs;"), std::string::npos) << vcd;
    EXPECT_EQ(body_of(vcd), "#0\n$dumpvars\nx!\n$end\n#203450521\n1!\n");
}

TEST(VcdWriter, RoundTripsThroughTheReader) {
    Timeline timeline;
    const SignalId pin = timeline.add_signal({"mcu", "PB5", SignalKind::Wire, 1, k16MHz});
    const SignalId port = timeline.add_signal({"mcu", "portb", SignalKind::Bus, 8, k16MHz});
    const SignalId temp = timeline.add_signal({"bed", "temp_degC", SignalKind::Real, 64, k20MHz});
    timeline.record(pin, 0, 0);
    timeline.record_real(temp, 0, 20.0);
    for (Cycle cycle = 100; cycle <= 1000; cycle += 100) {
        timeline.record(pin, cycle, (cycle / 100) % 2);
        timeline.record(port, cycle, cycle / 100);
        timeline.record_real(temp, cycle, 20.0 + static_cast<double>(cycle) / 1000.0);
    }
    const VcdDump dump = parse_vcd(format_vcd(timeline, vector_buses()));
    EXPECT_EQ(dump.version, "avrbench " AVRBENCH_VERSION);
    EXPECT_EQ(dump.timescale, "100ps");
    EXPECT_EQ(dump.timescale_fs, 100000u);
    ASSERT_EQ(dump.scopes, (std::vector<std::string>{"mcu", "bed"}));
    ASSERT_EQ(dump.variables.size(), 3u);

    const VcdVariable& v_pin = dump.at("mcu.PB5");
    EXPECT_EQ(v_pin.type, "wire");
    EXPECT_EQ(v_pin.width, 1u);
    ASSERT_EQ(v_pin.changes.size(), 11u);  // 0 at #0, then toggles at every 100 cycles
    EXPECT_EQ(v_pin.changes[0].time, 0u);
    EXPECT_EQ(v_pin.changes[0].value, "0");
    EXPECT_EQ(v_pin.changes[1].time, 62500u);  // cycle 100 x 625
    EXPECT_EQ(v_pin.changes[1].value, "1");

    const VcdVariable& v_port = dump.at("mcu.portb");
    EXPECT_EQ(v_port.width, 8u);
    ASSERT_EQ(v_port.changes.size(), 11u);  // bz, then 1..10
    EXPECT_EQ(v_port.changes[0].value, "z");
    EXPECT_EQ(v_port.changes[10].time, 625000u);
    EXPECT_EQ(v_port.changes[10].value, "00001010");

    const VcdVariable& v_temp = dump.at("bed.temp_degC");
    EXPECT_EQ(v_temp.type, "real");
    ASSERT_EQ(v_temp.changes.size(), 11u);
    for (std::size_t i = 1; i <= 10; ++i) {
        const double recorded = 20.0 + static_cast<double>(i * 100) / 1000.0;
        EXPECT_EQ(v_temp.changes[i].time, i * 100 * 500);  // 20 MHz: 500 x 100ps per cycle
        EXPECT_EQ(std::stod(v_temp.changes[i].value), recorded);
    }
    EXPECT_EQ(dump.end_time, 625000u);
}

TEST(VcdWriter, IdentifiersAreCompactBase94Codes) {
    EXPECT_EQ(vcd_identifier(0), "!");
    EXPECT_EQ(vcd_identifier(93), "~");
    // Bijective base 94, least significant digit first: 94 = (0, 0).
    EXPECT_EQ(vcd_identifier(94), "!!");
    EXPECT_EQ(vcd_identifier(95), "\"!");
    // The last 2-character code is 94 + 94^2 - 1 = 8929; 8930 is the first of 3.
    EXPECT_EQ(vcd_identifier(8929), "~~");
    EXPECT_EQ(vcd_identifier(8930), "!!!");
    std::set<std::string> seen;
    for (std::uint32_t i = 0; i < 20000; ++i) {
        const std::string code = vcd_identifier(i);
        const std::size_t expected_length = i < 94 ? 1 : i < 8930 ? 2 : 3;
        ASSERT_EQ(code.size(), expected_length) << i;
        for (const char c : code) ASSERT_TRUE(c >= 33 && c <= 126) << i;
        ASSERT_TRUE(seen.insert(code).second) << "duplicate code for " << i;
    }
}

TEST(VcdWriter, NineThousandSignalsKeepTheirOwnIdentifiers) {
    // 9000 > 94 + 8836: one-, two- and three-character codes in one dump.
    Timeline timeline;
    for (unsigned i = 0; i < 9000; ++i) {
        const SignalId id = timeline.add_signal(
            {"s" + std::to_string(i / 100), "w" + std::to_string(i), SignalKind::Wire, 1, k16MHz});
        timeline.record(id, id + 1, 1);
    }
    const VcdDump dump = parse_vcd(format_vcd(timeline));
    ASSERT_EQ(dump.variables.size(), 9000u);
    EXPECT_EQ(dump.scopes.size(), 90u);
    std::set<std::string> ids;
    for (unsigned i = 0; i < 9000; ++i) {
        const VcdVariable& var = dump.variables[i];
        ASSERT_EQ(var.full_name(), "s" + std::to_string(i / 100) + ".w" + std::to_string(i));
        ASSERT_TRUE(ids.insert(var.id).second) << var.id;
        ASSERT_EQ(var.changes.size(), 2u) << var.full_name();
        EXPECT_EQ(var.changes[1].time, (i + 1) * 625u);  // each signal saw only its own change
        EXPECT_EQ(var.changes[1].value, "1");
    }
}

TEST(VcdWriter, OutputIsByteIdenticalAcrossRuns) {
    auto build = [] {
        Timeline timeline;
        const SignalId a = timeline.add_signal({"mcu", "a", SignalKind::Wire, 1, k16MHz});
        const SignalId b = timeline.add_signal({"peer", "b", SignalKind::Real, 64, k20MHz});
        for (Cycle cycle = 0; cycle < 5000; cycle += 7) {
            timeline.record(a, cycle, cycle % 3);
            timeline.record_real(b, cycle + 3, static_cast<double>(cycle) * 0.25);
        }
        return timeline;
    };
    const Timeline first = build();
    const Timeline second = build();
    ScratchDir dir;
    write_vcd(first, dir.file("1.vcd"));
    write_vcd(second, dir.file("2.vcd"));
    const std::string text1 = trace_test::read_text(dir.file("1.vcd"));
    EXPECT_EQ(text1, trace_test::read_text(dir.file("2.vcd")));
    EXPECT_EQ(text1, format_vcd(first));
    EXPECT_EQ(text1.find("$date"), std::string::npos);  // nothing of the wall clock
}

TEST(VcdWriter, ReportsUnwritablePathAndUnknownSignal) {
    Timeline timeline;
    timeline.add_signal({"mcu", "a", SignalKind::Wire, 1, k16MHz});
    const std::string path = "/nonexistent-avrbench-dir/run.vcd";
    try {
        write_vcd(timeline, path);
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    timeline.record(7, 1, 1);  // id 7 was never registered
    EXPECT_THROW(format_vcd(timeline), std::out_of_range);
}

TEST(VcdWriter, WritesMillionsOfEventsInSeconds) {
    // One million events of all three kinds to a real file. Measured on the
    // development machine: 10 million events in 0.45-0.65 s (in record order),
    // 1.1 s when two clock domains need the sort. The bound only catches a
    // regression to per-character output, which takes minutes.
    constexpr std::size_t kEvents = 1000000;
    Timeline timeline;
    const SignalId step = timeline.add_signal({"x", "step", SignalKind::Wire, 1, k16MHz});
    const SignalId port = timeline.add_signal({"mcu", "portb", SignalKind::Bus, 8, k16MHz});
    const SignalId temp = timeline.add_signal({"bed", "temp_degC", SignalKind::Real, 64, k20MHz});
    timeline.reserve_events(kEvents);
    for (std::size_t i = 0; i < kEvents; ++i) {
        const Cycle cycle = i * 40;
        switch (i % 3) {
        case 0: timeline.record(step, cycle, (i / 3) & 1); break;
        case 1: timeline.record(port, cycle, i & 0xFF); break;
        default: timeline.record_real(temp, cycle, 20.0 + static_cast<double>(i % 977) * 0.01); break;
        }
    }
    ScratchDir dir;
    const auto start = std::chrono::steady_clock::now();
    const VcdResult result = write_vcd(timeline, dir.file("big.vcd"));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    RecordProperty("write_seconds_per_million_events", std::to_string(seconds));
    EXPECT_GT(result.value_changes, kEvents / 2);
    EXPECT_GT(std::filesystem::file_size(dir.file("big.vcd")), 10u * 1000 * 1000);
    EXPECT_LT(seconds, 10.0) << "1M events took " << seconds << " s";
}

}  // namespace vcd_writer_test
}  // namespace avrbench
