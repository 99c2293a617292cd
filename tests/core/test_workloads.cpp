// bench/perf's workload suite (firmware/workloads: nine CPU kernels) on the
// bench's predecoded core against simavr's own avr_run_one: the same
// result, the same cycle count and the same instruction count at the end
// label, kernel by kernel - the suite's speed figures compare like with like
// (docs/PERFORMANCE.md), and the fast core's 16/32-bit, MUL, LPM, call and
// interrupt paths agree with simavr's on real compiled code.
#include <gtest/gtest.h>

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

struct End {
    Cycle cycles;
    std::uint64_t steps;
    std::vector<std::uint8_t> result;
};

End run_to_end(const std::string& elf_name, bool predecoded) {
    McuOptions options;
    options.predecoded_core = predecoded;
    Mcu mcu(ElfImage::load(test::firmware(elf_name)), options);
    // Each kernel ends within 160 M cycles (10 s at 16 MHz); 20 s is the bound.
    while (mcu.run_until(mcu.cycle() + mcu.frequency_hz()) != StopReason::Halted && mcu.cycle() < 320'000'000) {
    }
    EXPECT_TRUE(mcu.halted()) << elf_name;
    return {mcu.cycle(), mcu.steps(), mcu.read_ram("result", 4)};
}

class Workloads : public ::testing::TestWithParam<int> {};

TEST_P(Workloads, ThePredecodedCoreEndsWhereSimavrsDoes) {
    const std::string elf = "workload_" + std::to_string(GetParam());
    const End fast = run_to_end(elf, true);
    const End simavr = run_to_end(elf, false);
    EXPECT_EQ(fast.cycles, simavr.cycles) << elf;
    EXPECT_EQ(fast.steps, simavr.steps) << elf;
    EXPECT_EQ(fast.result, simavr.result) << elf;
    EXPECT_GT(fast.cycles, 100'000'000u) << elf;  // the amount of work the suite was sized for
}

INSTANTIATE_TEST_SUITE_P(Kernels, Workloads, ::testing::Range(1, 10));

}  // namespace
}  // namespace avrbench
