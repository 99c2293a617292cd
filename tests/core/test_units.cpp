// Quantities as users write them (core/Units.hpp): SI values from the unit
// definitions (1 kohm = 1000 ohm, 1 min = 60 s, 1 deg = pi/180 rad, ...).
#include <gtest/gtest.h>

#include <cmath>

#include "core/Errors.hpp"
#include "core/Units.hpp"

namespace avrbench {
namespace {

TEST(Units, QuantitiesBecomeSiValues) {
    EXPECT_DOUBLE_EQ(parse_quantity("4.7kohm", Dimension::Resistance, "r"), 4700.0);
    EXPECT_DOUBLE_EQ(parse_quantity("1.9us", Dimension::Time, "t"), 1.9e-6);
    EXPECT_DOUBLE_EQ(parse_quantity("200mm", Dimension::Length, "l"), 0.2);
    EXPECT_DOUBLE_EQ(parse_quantity("16MHz", Dimension::Frequency, "f"), 16e6);
    EXPECT_DOUBLE_EQ(parse_quantity("25degC", Dimension::Temperature, "t"), 25.0);
    EXPECT_DOUBLE_EQ(parse_quantity("2 s", Dimension::Time, "t"), 2.0);  // a space between is allowed
    EXPECT_NEAR(parse_quantity("1.8deg", Dimension::Angle, "a"), 1.8 * M_PI / 180.0, 1e-15);
    EXPECT_DOUBLE_EQ(parse_quantity("80", Dimension::Dimensionless, "n"), 80.0);
}

TEST(Units, WrongOrMissingUnitsAreErrorsNamingTheValue) {
    try {
        parse_quantity("200", Dimension::Length, "travel");
        FAIL() << "a length without a unit was accepted";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("travel"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("needs a unit"), std::string::npos) << e.what();
    }
    EXPECT_THROW(parse_quantity("2mm", Dimension::Time, "t"), BadInput);        // another dimension
    EXPECT_THROW(parse_quantity("2furlongs", Dimension::Length, "l"), BadInput);  // unknown unit
    EXPECT_THROW(parse_quantity("mm", Dimension::Length, "l"), BadInput);         // no number
}

TEST(Units, DurationsArePicoseconds) {
    EXPECT_EQ(parse_duration_ps("250us", "d"), 250'000'000u);            // 250e-6 s * 1e12
    EXPECT_EQ(parse_duration_ps("1.5min", "d"), 90'000'000'000'000u);    // 90 s
    EXPECT_EQ(ps_from_seconds(0.5, "s"), 500'000'000'000u);
    EXPECT_THROW(ps_from_seconds(-1.0, "s"), BadInput);
    EXPECT_THROW(ps_from_seconds(std::nan(""), "s"), BadInput);
}

TEST(Units, IntegersAreWholeAndInRange) {
    EXPECT_EQ(parse_integer("1.6e3", "n", 0, 10000), 1600);
    EXPECT_THROW(parse_integer("1.5", "n", 0, 10), BadInput);
    EXPECT_THROW(parse_integer("11", "n", 0, 10), BadInput);
    EXPECT_THROW(checked_integer(1e300, "n", 0, 10), BadInput);  // never a bare cast
    EXPECT_EQ(checked_integer(-3.0, "n", -5, 5), -3);
}

TEST(Units, FrequenciesAreHertz) {
    EXPECT_EQ(parse_frequency_hz("20 MHz", "f"), 20'000'000u);
    EXPECT_EQ(parse_frequency_hz("32768", "f"), 32768u);
    EXPECT_EQ(parse_frequency_hz("32768Hz", "f"), 32768u);
}

}  // namespace
}  // namespace avrbench
