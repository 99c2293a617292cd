// Every numeric parameter of every part type has a valid range (declared
// beside it or its dimension's), and every default and preset value lies in
// it: a preset cannot be a value a user would be refused.
#include <gtest/gtest.h>

#include <cmath>

#include "parts/PartRegistry.hpp"
#include "core/Errors.hpp"
#include "parts/Params.hpp"

namespace avrbench {
namespace {

TEST(ParamRanges, EveryNumericParameterHasARangeHoldingItsDefaultsAndPresets) {
    std::size_t numeric = 0;
    for (const auto& [type_name, type] : part_types()) {
        for (const ParamSpec& spec : type.params) {
            if (spec.type != ParamType::Quantity && spec.type != ParamType::Integer) continue;
            ++numeric;
            const ParamRange r = range_of(spec);
            EXPECT_TRUE(std::isfinite(r.min) && std::isfinite(r.max) && r.min <= r.max) << type_name << "." << spec.name;
        }
        std::vector<std::map<std::string, std::string>> tables{{}};
        for (const auto& [preset, values] : type.presets) tables.push_back(values);
        for (const auto& table : tables) {
            try {
                resolve_params(type.params, table, {}, "p", type_name + ".yaml:1");
            } catch (const BadInput& e) {
                // A required parameter without a value is fine here; a value out of range is not.
                EXPECT_NE(std::string(e.what()).find("missing required parameter"), std::string::npos) << e.what();
            }
        }
    }
    EXPECT_GT(numeric, 60u);  // the registry's parts, not an empty list
}

TEST(ParamRanges, DimensionRangesAreThePhysicalOnes) {
    EXPECT_EQ(dimension_range(Dimension::Temperature).min, -273.15);  // absolute zero in degC
    EXPECT_EQ(dimension_range(Dimension::Resistance).min, 0);
    EXPECT_EQ(dimension_range(Dimension::Time).min, 0);
    EXPECT_EQ(dimension_range(Dimension::Time).max, 1e6);  // kMaxRunSeconds
}

}  // namespace
}  // namespace avrbench
