// resolve_params (parts/Params.hpp): defaults, presets and given values in
// that order of precedence, SI conversion, and one-line errors at file:line.
#include <gtest/gtest.h>

#include "core/Errors.hpp"
#include "parts/Params.hpp"

namespace avrbench {
namespace params_test {

const std::vector<ParamSpec> kSpecs = {
    {.name = "pulse", .type = ParamType::Quantity, .dimension = Dimension::Time, .default_value = "2us",
     .source = "assumed", .help = "pulse width"},
    {.name = "count", .type = ParamType::Integer, .default_value = "4", .min = 1, .max = 16},
    {.name = "mode", .type = ParamType::Choice, .default_value = "fast", .choices = {"fast", "slow"}},
    {.name = "to", .type = ParamType::Choice, .required = true, .choices = {"vcc", "gnd"}, .help = "the rail"},
};

std::string error_of(const std::vector<RawParam>& given) {
    try {
        resolve_params(kSpecs, {}, given, "p", "b.yaml:3");
    } catch (const BadInput& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(Params, GivenOverPresetOverDefault) {
    const ParamValues defaults = resolve_params(kSpecs, {}, {{"to", "vcc", "b.yaml:3"}}, "p", "b.yaml:3");
    EXPECT_DOUBLE_EQ(defaults.quantity("pulse"), 2e-6);
    EXPECT_EQ(defaults.integer("count"), 4);
    EXPECT_EQ(defaults.text("mode"), "fast");
    const ParamValues preset = resolve_params(kSpecs, {{"pulse", "5us"}, {"count", "8"}},
                                              {{"to", "gnd", "b.yaml:3"}, {"count", "2", "b.yaml:4"}}, "p", "b.yaml:3");
    EXPECT_DOUBLE_EQ(preset.quantity("pulse"), 5e-6);  // the preset's
    EXPECT_EQ(preset.integer("count"), 2);             // the given value wins
    EXPECT_EQ(preset.text("to"), "gnd");
}

TEST(Params, ErrorsNameTheLineAndTheProblem) {
    EXPECT_EQ(error_of({}), "b.yaml:3: part 'p': missing required parameter 'to' (the rail)");
    EXPECT_EQ(error_of({{"to", "vcc", "b.yaml:3"}, {"count", "17", "b.yaml:5"}}),
              "b.yaml:5: part 'p': count: '17' is outside 1 .. 16");
    EXPECT_EQ(error_of({{"to", "vdd", "b.yaml:4"}}), "b.yaml:4: part 'p': to: 'vdd' is not one of vcc, gnd");
    EXPECT_NE(error_of({{"to", "vcc", "b.yaml:3"}, {"pulse", "2mm", "b.yaml:6"}}).find("b.yaml:6: part 'p': pulse:"),
              std::string::npos);
    EXPECT_EQ(error_of({{"to", "vcc", "b.yaml:3"}, {"puls", "2us", "b.yaml:7"}}),
              "b.yaml:7: part 'p': unknown parameter 'puls' (known: pulse, count, mode, to)");
}

}  // namespace params_test
}  // namespace avrbench
