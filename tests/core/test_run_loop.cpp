// mcu/SimavrStep (with and without skipping idle loops) against simavr's
// own avr_run: every firmware the build
// makes runs 20 ms both ways, with every pin and USART0 traced, and must end
// in the same state (cycle, PC, registers, I/O and all of RAM, step count)
// with the same recorded timeline and the same findings. Firmware with a
// serial protocol also gets a few lines of input, so interrupts from the
// receiver are in the mix.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

extern "C" {
#include <sim_avr.h>
}

#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "support/EveryFirmware.hpp"
#include "support/Paths.hpp"
#include "trace/Recorder.hpp"
#include "trace/Timeline.hpp"

namespace avrbench {
namespace run_loop_test {

using test::all_firmware;
using test::expect_same_end;
using EndState = test::TracedEnd;

enum class Loop { Reference, Stepper, StepperSkippingIdleLoops };

EndState run(const std::string& name, Loop loop) {
    McuOptions options;
    options.reference_run_loop = loop == Loop::Reference;
    options.skip_idle_loops = loop == Loop::StepperSkippingIdleLoops;
    return test::run_traced(name, options);
}

TEST(RunLoop, SimavrStepEndsWhereAvrRunEndsOnEveryFirmware) {
    const auto names = all_firmware();
    ASSERT_GT(names.size(), 100u);  // the build's whole firmware set, not an empty folder
    for (const auto& name : names) {
        const EndState a = run(name, Loop::Reference), b = run(name, Loop::Stepper);
        expect_same_end(a, b, name);
        EXPECT_EQ(a.steps, b.steps) << name;
    }
}

// The idle-loop skipper (mcu/IdleLoopSkip.hpp) against simavr's avr_run on
// the same set: the same end state and byte-identical timelines, in fewer
// steps wherever a loop was skipped. It must also actually skip: waiting
// for the next received byte (uart_echo), for TWINT (twi_master), or in
// the Arduino core's loop() between Timer0 overflows.
TEST(RunLoop, SkippingIdleLoopsEndsWhereAvrRunEndsOnEveryFirmware) {
    const auto names = all_firmware();
    ASSERT_GT(names.size(), 100u);
    std::size_t skipped = 0;
    for (const auto& name : names) {
        const EndState a = run(name, Loop::Reference), b = run(name, Loop::StepperSkippingIdleLoops);
        expect_same_end(a, b, name);
        EXPECT_LE(b.steps, a.steps) << name;
        if (b.idle_jumps > 0) ++skipped;
    }
    EXPECT_GT(skipped, 10u) << "the skipper jumped on too few firmware to prove anything";
    for (const char* name : {"uart_echo", "twi_master", "ard_millis_delay"}) {
        EXPECT_GT(run(name, Loop::StepperSkippingIdleLoops).idle_jumps, 0u) << name;
    }
}

// Mcu::run_until_covering (the fuzz target's loop) is the run loop with every
// instruction's PC edge counted: it must end exactly where run_until ends,
// and the same run must give the same map. For busy_poll, whose main loop
// is a handful of instructions repeated, the map has few distinct edges but
// they saturate (255) after 20 ms.
TEST(RunLoop, CoveringRunEndsWhereThePlainRunEndsAndCountsEdges) {
    for (const char* name : {"busy_poll", "blink_timer1", "uart_echo", "printer3d_interp"}) {
        std::vector<std::uint8_t> first;
        for (int pass = 0; pass < 2; ++pass) {
            Mcu plain(ElfImage::load(test::firmware(name)));
            Mcu covered(ElfImage::load(test::firmware(name)));
            std::vector<std::uint8_t> map(1u << 16);
            PcEdgeMap edges{map.data(), static_cast<std::uint32_t>(map.size() - 1)};
            const Cycle end = plain.frequency_hz() / 50;  // 20 ms
            plain.run_until(end);
            for (Cycle c = 0; c < end;) {  // in 1 ms slices, as the fuzz target runs
                c = std::min<Cycle>(end, c + plain.frequency_hz() / 1000);
                covered.run_until_covering(c, edges);
            }
            EXPECT_EQ(plain.cycle(), covered.cycle()) << name;
            EXPECT_EQ(plain.pc_bytes(), covered.pc_bytes()) << name;
            EXPECT_TRUE(plain.data_memory() == covered.data_memory()) << name;
            const auto distinct = std::count_if(map.begin(), map.end(), [](std::uint8_t c) { return c != 0; });
            EXPECT_GE(distinct, 5) << name;
            if (std::string(name) == "busy_poll") {
                EXPECT_NE(std::count(map.begin(), map.end(), 0xFF), 0) << "the loop's edges saturate";
            }
            if (pass == 0) {
                first = map;
            } else {
                EXPECT_EQ(map, first) << name << ": the same run gives the same map";
            }
        }
    }
}

}  // namespace run_loop_test
}  // namespace avrbench

namespace avrbench {
namespace run_loop_test {

// run_until_sleep on the fast path (issue 37) against the general step of
// simavr's avr_run: on every firmware the build makes, 20 ms or up to the
// first SLEEP, the same end (cycle, PC, RAM, steps, sleeping or not). Where
// it stopped at a SLEEP, that is what the instruction in front of the PC is:
// 0x9588 (the AVR instruction set manual's SLEEP encoding).
TEST(RunLoop, RunUntilSleepStopsWhereTheGeneralStepStopsOnEveryFirmware) {
    const auto names = test::all_firmware();
    ASSERT_GT(names.size(), 100u);
    std::size_t slept = 0;
    for (const auto& name : names) {
        const ElfImage elf = ElfImage::load(test::firmware(name));
        McuOptions fast_options, skipping_options, reference_options;
        for (McuOptions* o : {&fast_options, &skipping_options, &reference_options}) test::set_board_mcu(name, elf, *o);
        fast_options.skip_idle_loops = false;  // the same steps as the reference
        skipping_options.skip_idle_loops = true;  // as `run --until-sleep` runs
        reference_options.reference_run_loop = true;
        reference_options.skip_idle_loops = false;
        Mcu fast(elf, fast_options), skipping(elf, skipping_options), reference(elf, reference_options);
        const Cycle end = fast.frequency_hz() / 50;
        const bool reference_slept = reference.run_until_sleep(end);
        for (Mcu* m : {&fast, &skipping}) {
            EXPECT_EQ(m->run_until_sleep(end), reference_slept) << name;
            EXPECT_EQ(m->cycle(), reference.cycle()) << name;
            EXPECT_EQ(m->pc_bytes(), reference.pc_bytes()) << name;
            EXPECT_TRUE(m->data_memory() == reference.data_memory()) << name;
        }
        EXPECT_EQ(fast.steps(), reference.steps()) << name;
        const bool fast_slept = reference_slept;
        if (fast_slept) {
            ++slept;
            const std::uint32_t at = fast.pc_bytes() - 2;
            const std::uint16_t word = static_cast<std::uint16_t>(fast.avr()->flash[at] | fast.avr()->flash[at + 1] << 8);
            EXPECT_EQ(word, 0x9588u) << name << " stopped at 0x" << std::hex << fast.pc_bytes();
        }
    }
    EXPECT_GT(slept, 3u);  // sleep_idle and the Arduino sketches that sleep, at least
}

}  // namespace run_loop_test
}  // namespace avrbench
