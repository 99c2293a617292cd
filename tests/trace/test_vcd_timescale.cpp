#include <gtest/gtest.h>

#include <stdexcept>

#include "trace/VcdTimescale.hpp"

namespace avrbench {
namespace {

TEST(VcdTimescale, SixteenMegahertzNeedsHundredPicoseconds) {
    // 16 MHz = 2^10 * 5^6 divides 10^10 but not 10^9: period 62.5 ns = 625 x 100ps.
    const VcdTimescale ts = VcdTimescale::for_clocks({16000000});
    EXPECT_TRUE(ts.exact());
    EXPECT_EQ(ts.exponent(), 10);
    EXPECT_EQ(ts.text(), "100ps");
    EXPECT_EQ(ts.units_per_cycle(16000000), 625u);
    // cycle 16000 at 16 MHz = 1 ms = 10^-3 s / 10^-10 s = 10,000,000 units.
    EXPECT_EQ(ts.units_at(16000, 16000000), 10000000u);
    // cycle 1 = 62.5 ns = 625 units; cycle 3 = 187.5 ns = 1875 units.
    EXPECT_EQ(ts.units_at(1, 16000000), 625u);
    EXPECT_EQ(ts.units_at(3, 16000000), 1875u);
}

TEST(VcdTimescale, TwentyMegahertzNeedsTenNanoseconds) {
    // 20 MHz = 2^8 * 5^7 divides 10^8: period 50 ns = 5 x 10ns.
    const VcdTimescale ts = VcdTimescale::for_clocks({20000000});
    EXPECT_TRUE(ts.exact());
    EXPECT_EQ(ts.text(), "10ns");
    EXPECT_EQ(ts.units_per_cycle(20000000), 5u);
    // cycle 20000 at 20 MHz = 1 ms = 100,000 units of 10 ns.
    EXPECT_EQ(ts.units_at(20000, 20000000), 100000u);
}

TEST(VcdTimescale, BothDomainsShareTheFinerUnit) {
    // max(10, 8) = 10 -> 100ps; 20 MHz period 50 ns = 500 units.
    const VcdTimescale ts = VcdTimescale::for_clocks({20000000, 16000000, 20000000});
    EXPECT_TRUE(ts.exact());
    EXPECT_EQ(ts.text(), "100ps");
    EXPECT_EQ(ts.units_per_cycle(20000000), 500u);
    EXPECT_EQ(ts.units_at(20000, 20000000), 10000000u);  // 1 ms
    EXPECT_EQ(ts.units_at(16000, 16000000), 10000000u);  // 1 ms
}

TEST(VcdTimescale, CoarsestUnitForOtherExactClocks) {
    // 8 MHz = 2^9 * 5^6 -> 10^-9 s: period 125 ns = 125 x 1ns.
    EXPECT_EQ(VcdTimescale::for_clocks({8000000}).text(), "1ns");
    EXPECT_EQ(VcdTimescale::for_clocks({8000000}).units_per_cycle(8000000), 125u);
    // 1 MHz = 10^6 -> 1us, one unit per cycle.
    EXPECT_EQ(VcdTimescale::for_clocks({1000000}).text(), "1us");
    // 1 Hz -> 1s; 4 Hz = 2^2 -> 10^-2 s = 10ms, 25 units per cycle.
    EXPECT_EQ(VcdTimescale::for_clocks({1}).text(), "1s");
    EXPECT_EQ(VcdTimescale::for_clocks({4}).text(), "10ms");
    EXPECT_EQ(VcdTimescale::for_clocks({4}).units_per_cycle(4), 25u);
    // No clock at all: nothing constrains the unit.
    EXPECT_EQ(VcdTimescale::for_clocks({}).text(), "1s");
}

TEST(VcdTimescale, TextForEveryExponent) {
    const char* const expected[] = {"1s",    "100ms", "10ms", "1ms", "100us", "10us", "1us", "100ns",
                                    "10ns",  "1ns",   "100ps", "10ps", "1ps", "100fs", "10fs", "1fs"};
    for (int k = 0; k <= 15; ++k) EXPECT_EQ(VcdTimescale(k).text(), expected[k]) << "exponent " << k;
    EXPECT_THROW(VcdTimescale(16), std::invalid_argument);
    EXPECT_THROW(VcdTimescale(-1), std::invalid_argument);
}

TEST(VcdTimescale, ClocksWithoutAnExactUnitRoundToFemtoseconds) {
    // 14.7456 MHz = 2^16 * 3^2 * 5^2: the factor 3 never divides a power of ten.
    const VcdTimescale ts = VcdTimescale::for_clocks({16000000, 14745600});
    EXPECT_FALSE(ts.exact());
    EXPECT_EQ(ts.text(), "1fs");
    EXPECT_EQ(ts.units_per_cycle(14745600), 0u);
    EXPECT_EQ(ts.units_per_cycle(16000000), 62500000u);  // still exact: 62.5 ns = 62,500,000 fs
    // 1 cycle = 10^15 / 14745600 fs = 67,816,840.277... -> 67,816,840.
    EXPECT_EQ(ts.units_at(1, 14745600), 67816840u);
    // 3 cycles = 203,450,520.83... -> 203,450,521 (rounds to nearest, not down).
    EXPECT_EQ(ts.units_at(3, 14745600), 203450521u);
    // 14,745,600 cycles = exactly 1 s = 10^15 fs.
    EXPECT_EQ(ts.units_at(14745600, 14745600), 1000000000000000u);
    // 2^20 Hz = 2^20 needs 10^-20 s, finer than VCD's 1fs.
    EXPECT_FALSE(VcdTimescale::for_clocks({1048576}).exact());
}

TEST(VcdTimescale, LongRunsStayExactAndOverflowIsReported) {
    const VcdTimescale ts = VcdTimescale::for_clocks({16000000});
    // One simulated day at 16 MHz: 86400 * 16e6 = 1,382,400,000,000 cycles
    // = 86400 s = 864,000,000,000,000 units of 100 ps.
    EXPECT_EQ(ts.units_at(1382400000000ULL, 16000000), 864000000000000ULL);
    // At 1 fs, 10^12 cycles of 14.7456 MHz = 6.78e19 fs > 2^64 = 1.84e19.
    const VcdTimescale fine = VcdTimescale::for_clocks({14745600});
    EXPECT_THROW((void)fine.units_at(1000000000000ULL, 14745600), std::overflow_error);
    EXPECT_THROW(VcdTimescale::for_clocks({0}), std::invalid_argument);
}

}  // namespace
}  // namespace avrbench
