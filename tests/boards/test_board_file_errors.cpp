// Every malformed board file gives one line naming file:line and the problem.
#include <gtest/gtest.h>

#include <fstream>

#include "boards/Board.hpp"
#include "parts/PartRegistry.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

// A valid board, line by line, so each case below can break one line.
const char* const kGood[] = {
    "mcus:",                                                                              // 1
    "  uno: {type: atmega328p, clock: 16MHz}",                                            // 2
    "parts:",                                                                             // 3
    "  x_driver: {type: step_dir_driver, preset: a4988}",                                 // 4
    "  x: {type: linear_axis, steps_per_mm: 80, travel: 200mm}",        // 5
    "  x_min: {type: limit_switch, position: 0mm}",                              // 6
    "nets:",                                                                              // 7
    "  x_step: [uno.PD2, x_driver.step]",                                                 // 8
    "  x_limit: [uno.PB1, x_min.out]",                                                    // 9
    "  x_motion: [x_driver.steps, x.drive]",                                              // 10
    "  x_carriage: [x.carriage, x_min.axis]",                                             // 11
};

std::string board_with(int line, const std::string& replacement) {
    std::string out;
    for (int i = 0; i < static_cast<int>(std::size(kGood)); ++i) {
        out += (i + 1 == line ? replacement : std::string(kGood[i])) + "\n";
    }
    return out;
}

std::string error_of(const std::string& text) {
    try {
        Board board(parse_board_text(text, "bad.yaml"), {{"uno", test::firmware("step_pattern")}});
    } catch (const BadInput& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(BoardFileErrors, TheGoodBoardBuilds) { EXPECT_EQ(error_of(board_with(0, "")), "(no error)"); }

struct Case {
    const char* name;
    int line;
    std::string replacement;
    std::string expected;  // the whole message
};

class BoardFileError : public ::testing::TestWithParam<Case> {};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

TEST_P(BoardFileError, NamesFileLineAndProblem) {
    const Case& c = GetParam();
    std::string expected = c.expected;
    if (auto at = expected.find("{elf}"); at != std::string::npos) expected.replace(at, 5, test::firmware("step_pattern"));
    if (auto at = expected.find("{types}"); at != std::string::npos) {
        // Every registered part type, in name order (the list grows with each part).
        std::string types;
        for (const auto& [name, type] : part_types()) types += (types.empty() ? "" : ", ") + name;
        expected.replace(at, 7, types);
    }
    const std::string error = error_of(board_with(c.line, c.replacement));
    if (expected.rfind("(starts) ", 0) == 0) {
        EXPECT_EQ(error.substr(0, expected.size() - 9), expected.substr(9));  // the rest lists this machine's folders
    } else {
        EXPECT_EQ(error, expected);
    }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BoardFileError,
    ::testing::Values(
        Case{"unknown_part_type", 4, "  x_driver: {type: step_dir_drvr}",
             "bad.yaml:4: part 'x_driver': unknown part type 'step_dir_drvr' (known: {types})"},
        Case{"unknown_pin", 8, "  x_step: [uno.PD9, x_driver.step]",
             "bad.yaml:8: unknown pin 'PD9': atmega328p has no such pin"},
        Case{"pin_the_part_lacks", 8, "  x_step: [uno.PC7, x_driver.step]",
             "bad.yaml:8: unknown pin 'PC7': atmega328p has no such pin"},
        Case{"unknown_owner", 9, "  x_limit: [uno.PB1, y_min.out]",
             "bad.yaml:9: 'y_min' is neither an MCU nor a part of this board"},
        Case{"missing_required", 4, "  x_driver: {type: pull_resistor}",
             "bad.yaml:4: part 'x_driver': missing required parameter 'to' (the rail the resistor goes to)"},
        Case{"unknown_unit", 5, "  x: {type: linear_axis, steps_per_mm: 80, travel: 200furlongs}",
             "bad.yaml:5: part 'x': travel: unknown unit 'furlongs' in '200furlongs' (expected m, mm, um, cm)"},
        Case{"wrong_unit", 4, "  x_driver: {type: step_dir_driver, preset: a4988, step_high_min: 2mm}",
             "bad.yaml:4: part 'x_driver': step_high_min: '2mm' is a length, expected a time (s, ms, us, ns, min, h)"},
        Case{"missing_unit", 5, "  x: {type: linear_axis, steps_per_mm: 80, travel: 200}",
             "bad.yaml:5: part 'x': travel: '200' needs a unit (m, mm, um, cm)"},
        Case{"unknown_parameter", 4, "  x_driver: {type: step_dir_driver, preset: a4988, step_hi_min: 2us}",
             "bad.yaml:4: part 'x_driver': unknown parameter 'step_hi_min' (known: preset, step_edge, step_high_min, "
             "step_low_min, dir_setup, dir_hold, max_step_rate, enable_active, microsteps, forward_dir, current, "
             "motor_supply, trace_resolution)"},
        Case{"bad_preset", 4, "  x_driver: {type: step_dir_driver, preset: a4989}",
             "bad.yaml:4: part 'x_driver': preset: 'a4989' is not one of a4988, drv8825, tmc2208, generic"},
        Case{"unknown_part_pin", 8, "  x_step: [uno.PD2, x_driver.stp]",
             "bad.yaml:8: part 'x_driver' (step_dir_driver) has no pin or port 'stp' (pins: step, dir, enable, ms1, "
             "ms2, ms3; ports: steps (steps), windings (windings))"},
        // Ports: one connection mechanism, checked by kind (parts/Part.hpp).
        Case{"port_not_connected", 10, "  x_dir: [uno.PD5, x_driver.dir]",
             "bad.yaml:5: part 'x' (linear_axis): port 'drive' is not connected: join it to a step_dir_driver's steps "
             "or a stepper motor's shaft in nets:"},
        Case{"port_kinds_differ", 11, "  x_carriage: [x_driver.windings, x_min.axis]",
             "bad.yaml:11: net 'x_carriage' joins a windings port (x_driver.windings) and a carriage port (x_min.axis)"},
        Case{"port_beside_a_pin", 11, "  x_carriage: [uno.PB2, x.carriage, x_min.axis]",
             "bad.yaml:11: net 'x_carriage' joins the pin uno.PB2 and the carriage port x.carriage: only analog "
             "outputs share a net with pins"},
        // Boot loaders (periph/memory/BootSection.hpp): the fuses come with them.
        Case{"bootloader_without_fuses", 2, "  uno: {type: atmega328p, clock: 16MHz, bootloader: optiboot_atmega328.hex}",
             "bad.yaml:2: MCU 'uno': a bootloader needs its fuses (e.g. fuses: {low: 0xFF, high: 0xDE, extended: 0xFD})"},
        Case{"fuse_not_a_byte", 2, "  uno: {type: atmega328p, clock: 16MHz, fuses: {low: 0xFF, high: 0x1DE, extended: 0xFD}}",
             "bad.yaml:2: MCU 'uno': fuses: high '0x1DE' is not a byte (0x00..0xFF)"},
        Case{"lock_not_a_byte", 2, "  uno: {type: atmega328p, clock: 16MHz, lock: 0x0G}",
             "bad.yaml:2: MCU 'uno': lock '0x0G' is not a byte (0x00..0xFF)"},
        Case{"fuse_missing", 2, "  uno: {type: atmega328p, clock: 16MHz, fuses: {low: 0xFF, high: 0xDE}}",
             "bad.yaml:2: MCU 'uno': fuses: missing 'extended' (give low, high and extended)"},
        Case{"bootloader_not_found", 2,
             "  uno: {type: atmega328p, clock: 16MHz, bootloader: nosuch.hex, fuses: {low: 0xFF, high: 0xDE, extended: 0xFD}}",
             "(starts) bad.yaml:2: bootloader 'nosuch.hex' not found (looked in "},
        // yaml-cpp reports the line where it noticed the missing ']': the next one.
        Case{"yaml_syntax", 8, "  x_step: [uno.PD2, x_driver.step",
             "bad.yaml:9: YAML syntax error: end of sequence flow not found"},
        Case{"bad_clock", 2, "  uno: {type: atmega328p, clock: 16MHZ}",
             "bad.yaml:2: MCU 'uno': clock: unknown unit 'MHZ' in '16MHZ' (expected Hz, kHz, MHz, rpm)"},
        Case{"unknown_section", 7, "netz:",
             "bad.yaml:7: unknown section 'netz' (expected board, description, extends, mcus, parts, nets, serial, labels)"},
        // Values no board can have (each range is written beside its check).
        // Declared ranges (ParamSpec min/max beside each parameter): steps_per_mm 1e-3..1e6.
        Case{"steps_per_mm_zero", 5, "  x: {type: linear_axis, steps_per_mm: 0, travel: 200mm}",
             "bad.yaml:5: part 'x': steps_per_mm: '0' is outside 0.001 .. 1e+06"},
        Case{"steps_per_mm_negative", 5, "  x: {type: linear_axis, steps_per_mm: -80, travel: 200mm}",
             "bad.yaml:5: part 'x': steps_per_mm: '-80' is outside 0.001 .. 1e+06"},
        Case{"steps_per_mm_huge", 5, "  x: {type: linear_axis, steps_per_mm: 1e300, travel: 200mm}",
             "bad.yaml:5: part 'x': steps_per_mm: '1e300' is outside 0.001 .. 1e+06"},
        Case{"travel_zero", 5, "  x: {type: linear_axis, steps_per_mm: 80, travel: 0mm}",
             "bad.yaml:5: part 'x': travel must be longer than 0 and at most 100 m"},
        Case{"switch_outside_travel", 6, "  x_min: {type: limit_switch, position: 300mm}",
             "bad.yaml:6: part 'x_min': position must lie within the axis' travel (0..200.000000 mm)"},
        // A length is never negative (dimension_range: 0..1000 m).
        Case{"switch_negative", 6, "  x_min: {type: limit_switch, position: -1mm}",
             "bad.yaml:6: part 'x_min': position: '-1mm' is outside 0 .. 1000 m"},
        Case{"bounce_edges_huge", 6, "  x_min: {type: limit_switch, position: 0mm, bounce_edges: 1e99}",
             "bad.yaml:6: part 'x_min': bounce_edges: '1e99' is outside 0 .. 1000"},
        Case{"microsteps_fraction", 4, "  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 1.5}",
             "bad.yaml:4: part 'x_driver': microsteps: '1.5' is not a whole number"},
        Case{"step_high_min_huge", 4, "  x_driver: {type: step_dir_driver, preset: a4988, step_high_min: 1e30s}",
             "bad.yaml:4: part 'x_driver': step_high_min: '1e30s' is outside 0 .. 3600 s"},
        Case{"microsteps_zero", 4, "  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 0}",
             "bad.yaml:4: part 'x_driver': microsteps: '0' is outside 1 .. 256"},
        Case{"current_negative", 4, "  x_driver: {type: step_dir_driver, preset: a4988, current: -1A}",
             "bad.yaml:4: part 'x_driver': current: '-1A' is outside 0 .. 1000 A"},
        // yaml-cpp would keep one of the two silently.
        Case{"duplicate_parameter", 5, "  x: {type: linear_axis, steps_per_mm: 80, steps_per_mm: 8, travel: 200mm}",
             "bad.yaml:5: duplicate key 'steps_per_mm'"},
        Case{"duplicate_part", 6, "  x: {type: linear_axis, steps_per_mm: 80, travel: 200mm}",
             "bad.yaml:6: duplicate key 'x'"},
        Case{"mcu_mismatch", 2, "  uno: {type: atmega2560, clock: 16MHz}",
             "{elf}: built for atmega328p, but bad.yaml:2 declares MCU 'uno' as atmega2560"}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(BoardFileErrors, TwoOutputsOnOneNet) {
    std::string text = board_with(0, "");
    text += "  y_limit: [uno.PB2, x_min.out]\n";  // x_min.out is already on x_limit
    EXPECT_EQ(error_of(text), "bad.yaml:12: 'x_min.out' is already on another net");
    // Two distinct switch outputs on one net.
    std::string two = board_with(9, "  x_limit: [uno.PB1, x_min.out, x_max.out]");
    two.insert(two.find("nets:"), "  x_max: {type: limit_switch, side: max}\n");
    EXPECT_EQ(error_of(two), "bad.yaml:10: net 'x_limit' is driven by two outputs: x_min.out and x_max.out");
}

TEST(BoardFileErrors, CliSaysItInOneLineWithExitCode2) {
    const auto dir = test::scratch_dir("board-cli");
    const auto path = dir / "bad.yaml";
    std::ofstream(path) << board_with(8, "  x_step: [uno.PD9, x_driver.step]");
    const auto r = test::run_command(std::string(::avrbench::test::cli()) + " run --board " + path.string() + " " +
                                         test::firmware("step_pattern"), dir);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, "avrbench: error: " + path.string() + ":8: unknown pin 'PD9': atmega328p has no such pin\n");
    EXPECT_EQ(r.out, "");
}

}  // namespace
}  // namespace avrbench
