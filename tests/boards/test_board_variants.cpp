// Board variants: `extends:` a base board; what the variant names replaces
// the base's declaration of that name, what it adds is added.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "parts/LimitSwitch.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace board_variants_test {

struct TempDir {
    std::filesystem::path path;
    TempDir() {
        path = std::filesystem::temp_directory_path() / ("avrbench-variants-" + std::to_string(::getpid()));
        std::filesystem::create_directories(path);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(path / name) << text;
        return (path / name).string();
    }
};

const char* const kBase = R"(board: base
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  x_driver: {type: step_dir_driver, preset: a4988}
  x: {type: linear_axis, steps_per_mm: 80, travel: 200mm}
  x_min: {type: limit_switch, position: 0mm}
nets:
  x_driver_steps: [x_driver.steps, x.drive]
  x_carriage: [x.carriage, x_min.axis]
  x_step: [uno.PD2, x_driver.step]
  x_limit: [uno.PB1, x_min.out]
)";

std::string error_of(const std::string& path) {
    try {
        load_board_file(path);
    } catch (const BadInput& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(BoardVariants, ReplaceByNameAndAdd) {
    TempDir dir;
    dir.write("base.yaml", kBase);
    const std::string variant = dir.write("variant.yaml", R"(board: variant
extends: base.yaml
parts:
  x_min: {type: limit_switch, position: 2mm, pull: push_pull}
  probe_pull: {type: pull_resistor, to: vcc}
nets:
  probe: [uno.PC5, probe_pull.pin]
)");
    const BoardSpec spec = load_board_file(variant);
    EXPECT_EQ(spec.name, "variant");
    EXPECT_EQ(spec.path, variant);
    ASSERT_EQ(spec.mcus.size(), 1u);
    ASSERT_EQ(spec.parts.size(), 4u);  // x_driver, x, x_min (replaced), probe_pull (added)
    const PartDecl* sw = spec.find_part("x_min");
    ASSERT_NE(sw, nullptr);
    // Replaced whole: the variant's parameters, none of the base's leftovers.
    ASSERT_EQ(sw->params.size(), 2u);
    EXPECT_EQ(sw->params[0].value, "2mm");
    EXPECT_NE(sw->location.find("variant.yaml:4"), std::string::npos) << sw->location;
    EXPECT_EQ(spec.nets.size(), 5u);  // x_driver_steps, x_carriage, x_step, x_limit from the base, probe added
    Board board(spec, {{"uno", test::firmware("sleep_idle")}});
    EXPECT_EQ(board.part_as<LimitSwitch>("x_min").name(), "x_min");
}

TEST(BoardVariants, ErrorsNameTheVariantLine) {
    TempDir dir;
    const std::string missing = dir.write("missing.yaml", "extends: nosuch.yaml\n");
    EXPECT_EQ(error_of(missing), missing + ":1: extends nosuch.yaml: no such board file");
    const std::string a = dir.write("a.yaml", "extends: b.yaml\n");
    dir.write("b.yaml", "extends: a.yaml\n");
    EXPECT_NE(error_of(a).find("'extends' nests more than 4 boards deep"), std::string::npos) << error_of(a);
    // An endpoint the variant puts on a second net is caught after the merge.
    dir.write("base.yaml", kBase);
    const std::string twice = dir.write("twice.yaml", "extends: base.yaml\nnets:\n  again: [uno.PD2, x_min.out]\n");
    EXPECT_NE(error_of(twice).find("'uno.PD2' is already on another net"), std::string::npos) << error_of(twice);
}

TEST(BoardVariants, OpticalEndstopRampsIsRampsWithPushPullSwitches) {
    const BoardSpec spec = load_board_file("ramps-1.4-optical-endstops");
    const BoardSpec base = load_board_file("ramps-1.4");
    EXPECT_EQ(spec.parts.size(), base.parts.size());
    EXPECT_EQ(spec.nets.size(), base.nets.size());
    for (const char* name : {"x_min", "y_min", "z_min"}) {
        const PartDecl* p = spec.find_part(name);
        ASSERT_NE(p, nullptr) << name;
        bool push_pull = false;
        for (const auto& param : p->params) push_pull = push_pull || (param.name == "pull" && param.value == "push_pull");
        EXPECT_TRUE(push_pull) << name;
    }
}

}  // namespace board_variants_test
}  // namespace avrbench
