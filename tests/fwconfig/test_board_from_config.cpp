// `avrbench board from-config`: configuration files of our own, written from
// each firmware's documented settings (tests/fixtures/fwconfig), read into
// boards. Expected values are the settings worked by hand (beside each), and
// the generated boards run our own firmware that reads endstops as Marlin
// does (firmware/boards/ramps_home).
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"
#include "fwconfig/BoardFromConfig.hpp"
#include "fwconfig/ConfigReaders.hpp"
#include "fwconfig/ConfigText.hpp"
#include "parts/Axis.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

const std::string kFixtures = test::source_path("tests/fixtures/fwconfig/");

ConfigFile fixture(const std::string& name) { return {name, test::slurp(kFixtures + name)}; }

std::string generate(const std::vector<ConfigFile>& files, const std::string& base = "") {
    const MachineConfig config = read_machine_config(detect_config_format(files), files);
    BoardFromConfigOptions options;
    options.name = "generated";
    options.base = base;
    for (const auto& f : files) options.inputs.push_back(f.path);
    return board_from_config(config, options);
}

bool has_line(const std::string& text, const std::string& line) {
    return text.find("\n" + line + "\n") != std::string::npos;
}

BoardSpec load_generated(const std::string& text, const std::string& name) {
    const auto dir = test::scratch_dir("from-config-" + name);
    std::ofstream(dir / "board.yaml") << text;
    return load_board_file((dir / "board.yaml").string());
}

TEST(ConfigText, ConditionsMacrosAndCommentsAsThePreprocessorSeesThem) {
    ConfigText c;
    c.add("#define A 2\n#define B (A * 3) /* six */\n#if B > 5 && ENABLED(A)\n#define C 1\n#elif 1\n#define C 2\n#endif\n"
          "#ifdef NOT_THERE\n#define D 1\n#else\n#define D 7\n#endif\n// #define E 1\n#define F { 1, 2.5, A + 1 }\n"
          "#define G 10 \\\n  + 5\nconst bool H = false;\n#define I(x) x\n",
          "c.h");
    EXPECT_EQ(c.number("B"), 6.0);
    EXPECT_EQ(c.number("C"), 1.0);   // 6 > 5 and A enabled: the #if branch
    EXPECT_EQ(c.number("D"), 7.0);   // NOT_THERE undefined: the #else
    EXPECT_FALSE(c.defined("E"));    // commented out
    EXPECT_EQ(c.numbers("F"), (std::vector<double>{1, 2.5, 3}));
    EXPECT_EQ(c.number("G"), 15.0);  // a continued line
    EXPECT_EQ(c.number("H"), 0.0);
    EXPECT_FALSE(c.defined("I"));    // a function-like macro is no setting
    EXPECT_EQ(c.cite("G"), "c.h:15: G 10 + 5");  // the first line, blanks run together
    EXPECT_EQ(c.evaluate("UNDEFINED_NAME + 1"), 1.0);  // the preprocessor's 0
}

// What a hostile or broken configuration does: no crash, no hang, a value
// it cannot read is "not a number". 100 000 nested parentheses (past the C
// standard's 63 levels, C11 5.2.4.1) overran the stack before; a macro
// enabled through itself (A is ENABLED(A)) recursed without end.
TEST(ConfigText, DeepNestingAndSelfReferenceAreNotNumbersAndLongValuesAreCitedShort) {
    ConfigText c;
    const std::string deep = std::string(100000, '(') + "1" + std::string(100000, ')');
    c.add("#define DEEP " + deep + "\n#define SHALLOW " + std::string(60, '(') + "1" + std::string(60, ')') +
              "\n#define A ENABLED(A)\n#define B B\n",
          "bad.h");
    EXPECT_EQ(c.number("DEEP"), std::nullopt);
    EXPECT_EQ(c.number("SHALLOW"), 1.0);  // what a preprocessor must take
    EXPECT_NE(c.number("A"), std::nullopt);  // some answer, at once
    EXPECT_EQ(c.number("B"), std::nullopt);
    EXPECT_EQ(c.cite("DEEP"), "bad.h:1: DEEP " + std::string(120, '(') + "... (200001 characters)");
    // Each macro used twice by the next: X15 = 2^15, each X evaluated once
    // (the fuzzer's inputs of this shape took 27 times longer before); two
    // macros through each other are not numbers.
    ConfigText d;
    std::string chain = "#define X0 1\n";
    for (int k = 1; k <= 15; ++k) chain += "#define X" + std::to_string(k) + " (X" + std::to_string(k - 1) + " + X" + std::to_string(k - 1) + ")\n";
    d.add(chain + "#define P (Q + 1)\n#define Q (P + 1)\n", "chain.h");
    EXPECT_EQ(d.number("X15"), 32768.0);
    EXPECT_EQ(d.number("P"), std::nullopt);
    // 256 nested #ifs are read (C11 asks for 63), the 257th is an error with its line.
    ConfigText e;
    std::string nested;
    for (int k = 0; k < 256; ++k) nested += "#if 1\n";
    nested += "#define INSIDE 7\n";
    for (int k = 0; k < 256; ++k) nested += "#endif\n";
    e.add(nested, "ok.h");
    EXPECT_EQ(e.number("INSIDE"), 7.0);
    try {
        ConfigText f;
        f.add("#if 1\n" + nested, "deep.h");
        ADD_FAILURE() << "no error";
    } catch (const BadInput& err) {
        EXPECT_EQ(std::string(err.what()), "deep.h:257: #if nested more than 256 deep");
    }
}

TEST(BoardFromConfig, MarlinSettingsBecomeTheRampsPartsWithTheirLines) {
    const std::string text = generate({fixture("marlin_ramps.h")});
    EXPECT_TRUE(has_line(text, "extends: ramps-1.4")) << text;
    // X: 78.7402 steps/mm; 0..200 mm between switches 2 mm inside: 204 mm, start 102 mm.
    EXPECT_TRUE(has_line(text, "  x: {type: linear_axis, steps_per_mm: 78.7402, travel: 204mm, start_position: 102mm}")) << text;
    // INVERT_X_DIR true (the #else of `#if 0`): DIR low is +; X_ENABLE_ON 0.
    EXPECT_TRUE(has_line(text, "  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 16, forward_dir: low, enable_active: low}")) << text;
    EXPECT_NE(text.find("marlin_ramps.h:28: INVERT_X_DIR true"), std::string::npos) << text;
    // X_MIN_ENDSTOP_INVERTING false with pull-ups: triggered high, a normally-closed switch to GND.
    EXPECT_TRUE(has_line(text, "  x_min: {type: limit_switch, side: min, position: 2mm, contact: NC, switched_to: gnd, pull: internal_up}")) << text;
    // Y homes to a max switch (USE_YMAX_PLUG, Y_HOME_DIR 1), inverting: triggered low.
    // 0..180 mm: travel 184 mm, the switch at 184 - 2 = 182 mm, on the board's Y_MAX input (D15 = PJ0).
    EXPECT_TRUE(has_line(text, "  y: {type: linear_axis, steps_per_mm: 80, travel: 184mm, start_position: 92mm}")) << text;
    EXPECT_TRUE(has_line(text, "  y_max_switch: {type: limit_switch, side: max, position: 182mm, contact: NO, switched_to: gnd, pull: internal_up}")) << text;
    EXPECT_TRUE(has_line(text, "  y_max_switch: [mega.PJ0, y_max_switch.out]")) << text;
    // Z: 200.0*8/3 = 533.33... steps/mm; E: 760*1.1 = 836.
    EXPECT_NE(text.find("steps_per_mm: 533.3333333, travel: 154mm"), std::string::npos) << text;
    EXPECT_NE(text.find("filament_steps_per_mm: 836}"), std::string::npos) << text;
    // The oracle: X's 0 at its switch (2 mm); Y calls its max switch (182 mm) 180, so its 0 is at 2 mm.
    EXPECT_NE(text.find("home_x: 2mm, home_y: 2mm, home_z: 2mm, soft_min_x: 0mm, soft_max_x: 200mm, soft_min_y: 0mm, "
                        "soft_max_y: 180mm, soft_min_z: 0mm, soft_max_z: 150mm"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("hotend_thermistor: {type: thermistor, preset: epcos_b57560g104f"), std::string::npos) << text;
    EXPECT_NE(text.find("#   marlin_ramps.h:9: TEMP_SENSOR_BED 5: the bench has no preset"), std::string::npos) << text;
    // And it is a board: it loads and its parts check.
    Board board(load_generated(text, "marlin"), {{"mega", test::firmware("ramps_home")}});
    // 102 mm is 8031.5 steps at 78.7402 steps/mm: the carriage starts within a step of it.
    EXPECT_NEAR(board.part_as<Axis>("x").position_mm(), 102.0, 1 / 78.7402);
}

// ramps_home reads the min endstops as Marlin does (HIGH = triggered, or
// LOW built inverted) and homes X and Y: from 102 mm to the switch at 2 mm
// is 100 mm = 8000 steps at 80 steps/mm.
struct Homing {
    unsigned x_steps, y_steps;
    double x_mm;
    std::size_t findings;
};
Homing home_on(const std::string& text, const std::string& firmware) {
    Board board(load_generated(text, firmware), {{"mega", test::firmware(firmware)}});
    board.run_for_seconds(2.5);
    Mcu& mega = board.mcu("mega");
    EXPECT_EQ(mega.read_ram_u8("done"), 1);
    return {mega.read_ram_u16("x_steps"), mega.read_ram_u16("y_steps"), board.part_as<Axis>("x").position_mm(),
            board.findings().size()};
}

TEST(BoardFromConfig, AFirmwareHomesOnTheBoardMadeFromItsEndstopSettings) {
    const Homing plain = home_on(generate({fixture("marlin_home.h")}), "ramps_home");
    EXPECT_EQ(plain.x_steps, 8000u);
    EXPECT_EQ(plain.y_steps, 8000u);
    EXPECT_DOUBLE_EQ(plain.x_mm, 2.0);
    EXPECT_EQ(plain.findings, 0u);
    // The same configuration with inverting endstops (a first file defines
    // INVERTED_ENDSTOPS): normally-open switches, and the inverted build homes the same.
    const Homing inverted = home_on(generate({{"inverted.h", "#define INVERTED_ENDSTOPS\n"}, fixture("marlin_home.h")}),
                                    "ramps_home_inverted");
    EXPECT_EQ(inverted.x_steps, 8000u);
    EXPECT_EQ(inverted.findings, 0u);
}

TEST(BoardFromConfig, SprinterConstBoolsAndItsStepsMacro) {
    const std::string text = generate({fixture("sprinter.h")});
    // MOTHERBOARD 33: RAMPS; 3200/1.25 = 2560 steps/mm on Z, 0..100 mm: 104 mm.
    EXPECT_TRUE(has_line(text, "extends: ramps-1.4")) << text;
    EXPECT_NE(text.find("steps_per_mm: 2560, travel: 104mm"), std::string::npos) << text;
    // X_ENDSTOP_INVERT true with ENDSTOPPULLUPS: triggered low, normally open.
    EXPECT_TRUE(has_line(text, "  x_min: {type: limit_switch, side: min, position: 2mm, contact: NO, switched_to: gnd, pull: internal_up}")) << text;
    EXPECT_NE(text.find("  z_driver: {type: step_dir_driver, preset: a4988, microsteps: 16, forward_dir: low"), std::string::npos) << text;
    EXPECT_NE(text.find("Sprinter's configuration"), std::string::npos);
}

TEST(BoardFromConfig, RepetierEnablesActiveHighAndSwitchesAtBothEnds) {
    const std::string text = generate({fixture("repetier.h")});
    EXPECT_NE(text.find("  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 16, forward_dir: high, enable_active: high}"),
              std::string::npos)
        << text;
    // X_MIN_POS 0 + X_MAX_LENGTH 250: travel 254 mm; the max switch at 252 mm on X_MAX (D2 = PE4).
    EXPECT_TRUE(has_line(text, "  x: {type: linear_axis, steps_per_mm: 72.72, travel: 254mm, start_position: 127mm}")) << text;
    EXPECT_TRUE(has_line(text, "  x_max_switch: {type: limit_switch, side: max, position: 252mm, contact: NO, switched_to: gnd, pull: internal_up}")) << text;
    EXPECT_TRUE(has_line(text, "  x_max_switch: [mega.PE4, x_max_switch.out]")) << text;
    EXPECT_NE(text.find("filament_steps_per_mm: 255}"), std::string::npos) << text;
    // Its 0 after G28 is 1 mm off the switch: the oracle gets no home (G28 ends the judging).
    EXPECT_EQ(text.find("home_x:"), std::string::npos) << text;
    EXPECT_NE(text.find("no home: repetier.h:22: ENDSTOP_X_BACK_ON_HOME 1: Repetier moves back after homing"), std::string::npos)
        << text;
    // And the oracle says so when a G28 ends its judging.
    EXPECT_NE(text.find("motion: {type: motion_oracle, no_home_because: \"repetier.h:22: ENDSTOP_X_BACK_ON_HOME 1: Repetier moves "
                        "back after homing and its 0 is not at the switch\""),
              std::string::npos)
        << text;
    load_generated(text, "repetier");
}

TEST(BoardFromConfig, TeacupStepsPerMetreAndFlagsThatExistOrNot) {
    const std::string text = generate({fixture("board.ramps-teacup.h"), fixture("teacup_printer.h")});
    // 40000 steps/m = 40 steps/mm; X_MIN 0 .. X_MAX 200: 204 mm.
    EXPECT_TRUE(has_line(text, "  x: {type: linear_axis, steps_per_mm: 40, travel: 204mm, start_position: 102mm}")) << text;
    // X_INVERT_DIR: DIR low is +; X_INVERT_ENABLE: active low; Y_INVERT_DIR absent: high.
    EXPECT_NE(text.find("  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 16, forward_dir: low, enable_active: low}"),
              std::string::npos)
        << text;
    // No USE_INTERNAL_PULLUPS: a switch that drives both levels; X_INVERT_MIN: low when triggered.
    EXPECT_TRUE(has_line(text, "  x_min: {type: limit_switch, side: min, position: 2mm, contact: NC, switched_to: vcc, pull: push_pull}")) << text;
    EXPECT_TRUE(has_line(text, "  y_min: {type: limit_switch, side: min, position: 2mm, contact: NO, switched_to: vcc, pull: push_pull}")) << text;
    // Teacup zeroes where the switch releases: no home for the oracle.
    EXPECT_EQ(text.find("home_x:"), std::string::npos) << text;
    load_generated(text, "teacup");
}

TEST(BoardFromConfig, AGrblSettingsDumpMovesTheShieldsSwitchToTheHomingEnd) {
    const std::string text = generate({fixture("grbl-settings.txt")});
    EXPECT_TRUE(has_line(text, "extends: arduino-uno-cnc-shield-v3")) << text;
    // $3=1: X's direction inverted, so DIR high is + on X; Y and Z keep grbl's DIR low.
    EXPECT_NE(text.find("  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 16, forward_dir: high"), std::string::npos) << text;
    EXPECT_NE(text.find("  y_driver: {type: step_dir_driver, preset: a4988, microsteps: 16, forward_dir: low"), std::string::npos) << text;
    // $130=300: travel 304 mm (2 mm of room past each switch). $23=2: Y homes
    // negative, X and Z positive: X's switch at 304 - 2 = 302 mm.
    EXPECT_TRUE(has_line(text, "  x: {type: linear_axis, steps_per_mm: 250, travel: 304mm, start_position: 152mm}")) << text;
    EXPECT_TRUE(has_line(text, "  x_limit: {type: limit_switch, side: max, position: 302mm, contact: NO, switched_to: gnd, pull: internal_up}")) << text;
    EXPECT_TRUE(has_line(text, "  y_limit: {type: limit_switch, side: min, position: 2mm, contact: NO, switched_to: gnd, pull: internal_up}")) << text;
    load_generated(text, "grbl");
}

TEST(BoardFromConfig, KlipperPinsRotationDistancesAndEndstops) {
    const std::string text = generate({fixture("printer.cfg")});
    EXPECT_TRUE(has_line(text, "extends: ramps-1.4")) << text;
    // 200 full steps * 16 / 40 mm = 80 steps/mm; Y: 400 * 16 / 32 = 200.
    EXPECT_TRUE(has_line(text, "  x: {type: linear_axis, steps_per_mm: 80, travel: 204mm, start_position: 102mm}")) << text;
    EXPECT_NE(text.find("  y: {type: linear_axis, steps_per_mm: 200,"), std::string::npos) << text;
    // dir_pin: !PF1 -> DIR low is +; enable_pin: !PD7 -> active low.
    EXPECT_NE(text.find("  x_driver: {type: step_dir_driver, preset: a4988, microsteps: 16, forward_dir: low, enable_active: low}"),
              std::string::npos)
        << text;
    // endstop_pin: ^!PE5: pull-up, triggered low (normally open); ^PJ1: triggered high (normally closed).
    EXPECT_TRUE(has_line(text, "  x_min: {type: limit_switch, side: min, position: 2mm, contact: NO, switched_to: gnd, pull: internal_up}")) << text;
    EXPECT_TRUE(has_line(text, "  y_min: {type: limit_switch, side: min, position: 2mm, contact: NC, switched_to: gnd, pull: internal_up}")) << text;
    EXPECT_NE(text.find("a virtual endstop (probe), not a switch"), std::string::npos) << text;
    load_generated(text, "klipper");
}

TEST(BoardFromConfig, WithoutABoardItSaysWhichSettingAndAsksForBase) {
    const std::vector<ConfigFile> files{{"Configuration.h", "#define MOTHERBOARD BOARD_ULTIMAKER\n#define DEFAULT_AXIS_STEPS_PER_UNIT {80,80,400,100}\n"}};
    try {
        generate(files);
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_EQ(std::string(e.what()), "Configuration.h:1: MOTHERBOARD BOARD_ULTIMAKER: no standard board for it: give the "
                                         "board to extend with --base (avrbench boards lists them)");
    }
    EXPECT_NE(generate(files, "ramps-1.4").find("extends: ramps-1.4"), std::string::npos);
    EXPECT_THROW(detect_config_format({{"notes.txt", "hello\n"}}), BadInput);
}

TEST(BoardFromConfig, TheSmartControllerOnRampsExtendsTheBoardWithIt) {
    // Marlin's REPRAP_DISCOUNT_SMART_CONTROLLER on RAMPS: the 20x4 LCD, the knob and the SD slot of pins_RAMPS.h.
    const std::string text =
        generate({{"Configuration.h", "#define MOTHERBOARD 33\n#define REPRAP_DISCOUNT_SMART_CONTROLLER\n"
                                      "#define DEFAULT_AXIS_STEPS_PER_UNIT {80,80,400,100}\n"}});
    EXPECT_TRUE(has_line(text, "extends: ramps-1.4-smart-controller")) << text;
    EXPECT_NE(text.find("(Configuration.h:1: MOTHERBOARD 33; Configuration.h:2: REPRAP_DISCOUNT_SMART_CONTROLLER)"), std::string::npos)
        << text;
    Board board(load_generated(text, "smart"), {{"mega", test::firmware("ramps_home")}});
    EXPECT_EQ(board.part("lcd").type(), "hd44780");
    EXPECT_EQ(board.part("x").type(), "linear_axis");
}

TEST(BoardFromConfig, AThermocoupleOnAnAd595ReplacesTheThermistor) {
    // Marlin 1.0's Configuration.h: "-1 is thermocouple with AD595" (its stock TEMP_SENSOR_0).
    const std::string text = generate({{"Configuration.h", "#define MOTHERBOARD 33\n#define TEMP_SENSOR_0 -1\n#define DEFAULT_AXIS_STEPS_PER_UNIT {80,80,400,100}\n"}});
    EXPECT_TRUE(has_line(text, "  # a thermocouple on an AD595: Configuration.h:2: TEMP_SENSOR_0 -1")) << text;
    EXPECT_TRUE(has_line(text, "  hotend_thermistor: {type: thermocouple_amplifier, preset: ad595}")) << text;
    // The base's nets (the plant's body, T0 = PK5) hold for the new part.
    Board board(load_generated(text, "ad595"), {{"mega", test::firmware("ramps_home")}});
    EXPECT_EQ(board.part("hotend_thermistor").type(), "thermocouple_amplifier");
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// The command line: a file written where -o says, errors in one line with
// exit 2, and an input file never overwritten (docs/CLI.md).
TEST(BoardFromConfigCli, WritesTheBoardAndRefusesToOverwriteAnInput) {
    const auto dir = test::scratch_dir("from-config-cli");
    const std::string cfg = test::source_path("tests/fixtures/fwconfig/printer.cfg");
    const auto ok = test::run_command(std::string(test::cli()) + " board from-config " + cfg + " -o " + (dir / "k.yaml").string(), dir);
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_NE(test::slurp(dir / "k.yaml").find("extends: ramps-1.4"), std::string::npos);
    EXPECT_EQ(ok.err, "wrote " + (dir / "k.yaml").string() + " (klipper configuration)\n");

    std::filesystem::copy_file(cfg, dir / "copy.cfg");
    const std::string before = test::slurp(dir / "copy.cfg");
    const auto clobber = test::run_command(std::string(test::cli()) + " board from-config " + (dir / "copy.cfg").string() + " -o " +
                                               (dir / "copy.cfg").string(), dir);
    EXPECT_EQ(clobber.exit_code, 2);
    EXPECT_EQ(clobber.err, "avrbench: error: -o " + (dir / "copy.cfg").string() + ": that is an input file (inputs are never written)\n");
    EXPECT_EQ(test::slurp(dir / "copy.cfg"), before);

    const auto format = test::run_command(std::string(test::cli()) + " board from-config " + cfg + " --format marlyn", dir);
    EXPECT_EQ(format.exit_code, 2);
    EXPECT_EQ(format.err, "avrbench: error: --format marlyn: not one of marlin, repetier, teacup, grbl, grbl-settings, klipper\n");
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(BoardFromConfig, APrusaVariantGivesTheTmcDirectionsAndStallTuning) {
    const std::string text = generate({fixture("prusa_variant.h")});
    EXPECT_TRUE(has_line(text, "extends: prusa-mk3s")) << text;
    // INVERT_X_DIR 1: DIR low is +; TMC2130_SG_THRS_X 3; 1/16 from TMC2130_USTEPS_XY.
    EXPECT_TRUE(has_line(text, "  x_driver: {type: tmc2130, microsteps: 16, forward_dir: low, stall_sgt: 3}")) << text;
    EXPECT_TRUE(has_line(text, "  z_driver: {type: tmc2130, microsteps: 16, forward_dir: low, stall_sgt: 4}")) << text;
    // 3200/8 = 400 steps/mm; no switches: the board's travel and start stay.
    EXPECT_TRUE(has_line(text, "  z: {type: linear_axis, steps_per_mm: 400, travel: 210mm, start_position: 20mm}")) << text;
    EXPECT_NE(text.find("filament_steps_per_mm: 280}"), std::string::npos) << text;
    load_generated(text, "prusa");
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(BoardFromConfig, Marlin21HitStatesAndPlugsFromTheHomingDirection) {
    const std::string text = generate({fixture("marlin2.h")});
    // X_MIN_ENDSTOP_HIT_STATE HIGH with pull-ups: a normally-closed switch to GND;
    // Y's LOW: normally open. The min ends have switches (X/Y_HOME_DIR -1).
    EXPECT_TRUE(has_line(text, "  x_min: {type: limit_switch, side: min, position: 2mm, contact: NC, switched_to: gnd, pull: internal_up}")) << text;
    EXPECT_TRUE(has_line(text, "  y_min: {type: limit_switch, side: min, position: 2mm, contact: NO, switched_to: gnd, pull: internal_up}")) << text;
    // X_BED_SIZE 220: travel 224 mm; Z_MAX_POS 250: 254 mm at 400 steps/mm.
    EXPECT_TRUE(has_line(text, "  x: {type: linear_axis, steps_per_mm: 80, travel: 224mm, start_position: 112mm}")) << text;
    EXPECT_TRUE(has_line(text, "  z: {type: linear_axis, steps_per_mm: 400, travel: 254mm, start_position: 127mm}")) << text;
    EXPECT_NE(text.find("  y_driver: {type: step_dir_driver, preset: a4988, microsteps: 16, forward_dir: low"), std::string::npos) << text;
    load_generated(text, "marlin2");
}

}  // namespace
}  // namespace avrbench
