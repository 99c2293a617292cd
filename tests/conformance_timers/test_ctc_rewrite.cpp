// CTC mode, OCRnA rewritten below TCNTn (firmware/conformance/timers/tmr_ctc_rewrite).
//
// ATmega328P datasheet §16.9.2 (and §15.7.2, §18.7.2; ATmega2560 §17.9.2;
// ATmega32 Timer/Counter1 "Clear Timer on Compare Match (CTC) Mode"): "If
// the new value written to OCR1A or ICR1 is lower than the current value of
// TCNT1, the counter will miss the compare match. The counter will then have
// to count to its maximum value (0xFFFF) and wrap around starting at 0x0000
// before the compare match can occur." With clk/1 and OCnA toggling on each
// match, the interval across the rewrite is (MAX + 1) + (NEW + 1) cycles:
// 65536 + 100 = 65636 for the 16-bit timers (OCRnA 999 -> 99), 256 + 50 = 306
// for the 8-bit ones (199 -> 49). TOVn is set on the way (§16.9.2: "TOV1 Flag
// is set in the same timer clock cycle that the counter counts from MAX to 0x0000").
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

struct Rewrite {
    const char* pin;
    Cycle before;  // OLD + 1
    Cycle across;  // MAX + 1 + NEW + 1
    Cycle after;   // NEW + 1
};

::testing::AssertionResult one_wrap(const std::vector<Cycle>& intervals, const Rewrite& r) {
    std::size_t i = 0;
    while (i < intervals.size() && intervals[i] == r.before) ++i;
    if (i == 0 || i >= intervals.size() || intervals[i] != r.across) {
        ::testing::AssertionResult f = ::testing::AssertionFailure();
        f << r.pin << ": expected " << r.before << "... then " << r.across << ", got";
        for (std::size_t k = 0; k < intervals.size() && k < 16; ++k) f << ' ' << intervals[k];
        return f;
    }
    std::vector<Cycle> rest(intervals.begin() + static_cast<std::ptrdiff_t>(i) + 1, intervals.end());
    auto after = all_equal(rest, r.after, 5);
    if (!after) return after << " (" << r.pin << " after the wrap)";
    return ::testing::AssertionSuccess();
}

void expect_rewrite(const TimerPart& part, const std::vector<Rewrite>& rewrites, std::uint8_t all_timers) {
    Mcu mcu(timer_firmware("tmr_ctc_rewrite", part));
    std::vector<std::unique_ptr<PinLog>> logs;
    for (const auto& r : rewrites) logs.push_back(std::make_unique<PinLog>(mcu, r.pin));
    mcu.run_for(80000);  // start + a few old periods + 65636 + a few new ones
    ASSERT_EQ(mcu.read_ram_u8("done"), 1);
    for (std::size_t i = 0; i < rewrites.size(); ++i) EXPECT_TRUE(one_wrap(logs[i]->intervals(), rewrites[i]));
    EXPECT_EQ(mcu.read_ram_u8("tov_at_match"), all_timers);
}

TEST(TimerCtcRewrite, OcrBelowTcntWrapsThroughMaxAtmega328p) {
    expect_rewrite(kAtmega328p, {{"PB1", 1000, 65636, 100}, {"PD6", 200, 306, 50}, {"PB3", 200, 306, 50}}, 0x07);
}

TEST(TimerCtcRewrite, OcrBelowTcntWrapsThroughMaxAtmega2560) {
    expect_rewrite(kAtmega2560,
                   {{"PB5", 1000, 65636, 100},
                    {"PB7", 200, 306, 50},
                    {"PB4", 200, 306, 50},
                    {"PE3", 1000, 65636, 100},
                    {"PH3", 1000, 65636, 100},
                    {"PL3", 1000, 65636, 100}},
                   0x3F);
}

TEST(TimerCtcRewrite, OcrBelowTcntWrapsThroughMaxAtmega32) {
    expect_rewrite(kAtmega32, {{"PD5", 1000, 65636, 100}, {"PB3", 200, 306, 50}, {"PD7", 200, 306, 50}}, 0x07);
}

}  // namespace
}  // namespace avrbench::test::timers
