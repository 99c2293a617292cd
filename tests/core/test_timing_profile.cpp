// The timing profile (mcu/TimingProfile.hpp) against hand counts from the
// firmware listings and the datasheet's interrupt response.
#include <gtest/gtest.h>

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "mcu/TimingProfile.hpp"
#include "support/Paths.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

// blink_timer1 (ATmega328P, 16 MHz): Timer1 CTC, compare match A (vector 11)
// every (249 + 1) * 64 = 16000 cycles; main ends in `sei; rjmp .-2`.
TEST(TimingProfile, BlinkTimer1sIsrMatchesItsListing) {
    Mcu mcu(ElfImage::load(test::firmware("blink_timer1")));
    mcu.enable_profile();
    mcu.run_until(1'600'000);  // 100 ms
    const TimingProfiler& p = *mcu.profile();
    ASSERT_EQ(p.vectors().count(11), 1u);
    const VectorProfile& v = p.vectors().at(11);
    // The first match 16000 cycles after Timer1 starts (a few dozen cycles
    // into main), then every 16000: 99 entries in 1.6 M cycles.
    EXPECT_EQ(v.runs, 99u);
    // blink_timer1.lst, __vector_11 and its slot: jmp 3, push r1 2, push r0 2,
    // in 1, push r0 2, eor 1, push r24 2, ldi 1, out 1, pop r24 2, pop r0 2,
    // out 1, pop r0 2, pop r1 2, reti 4 = 28 cycles.
    EXPECT_EQ(v.inclusive_cycles.min(), 28u);
    EXPECT_EQ(v.inclusive_cycles.max(), 28u);
    EXPECT_EQ(v.exclusive_cycles.max(), 28u);  // nothing nests in it
    EXPECT_EQ(v.max_depth, 1);
    // ATmega328P §7.7: 4 cycles of response after the instruction in
    // progress completes; the 2-cycle rjmp may have one cycle left.
    EXPECT_GE(v.latency_cycles.min(), 4u);
    EXPECT_LE(v.latency_cycles.max(), 5u);
    // RAMEND 0x08FF; `call main` pushes 2 bytes (SP 0x08FD), the interrupt
    // the return address (0x08FB), the ISR 4 registers: 0x08F7.
    EXPECT_EQ(p.lowest_sp(), 0x08F7);
    // I = 0 in each ISR from its first instruction to the end of RETI, which
    // sets I again: 28 cycles (the reset's stretch to main's sei is apart).
    EXPECT_EQ(p.longest_interrupts_off(), 28u);
    EXPECT_EQ(p.longest_off_vector(), 11);
    EXPECT_LT(p.first_sei_cycle(), 16000u);
    // Every cycle is accounted for: executed, asleep or jumped over.
    EXPECT_EQ(p.active_cycles() + p.sleeping_cycles() + mcu.idle_cycles_skipped(), mcu.cycle());
    // The JSON gives each PC as a number and as the summary writes it.
    const std::string json = p.json();
    const auto at = json.find("\"pc\": ", json.find("\"interrupts_off\""));
    ASSERT_NE(at, std::string::npos) << json;
    const unsigned long pc = std::stoul(json.substr(at + 6));
    char hex[32];
    std::snprintf(hex, sizeof hex, "\"pc_hex\": \"0x%04lx\"", pc);
    EXPECT_NE(json.find(hex, at), std::string::npos) << json;
}

// grbl_stepper (firmware/boards/grbl_stepper/README.md): the step vector
// (Timer1 COMPA, vector 11) re-enables interrupts and Timer0's overflow
// (vector 16) nests inside it to end the STEP pulse.
TEST(TimingProfile, NestedIsrTimeIsAttributedToTheInnerVector) {
    Bench bench(test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml"), test::firmware("grbl_stepper"));
    bench.mcu().enable_profile();
    UartHostOptions host = default_host_options(bench.serial_port(""));
    host.family = FirmwareFamily::Generic;
    bench.host("", host).add_lines("X1600\n");
    bench.run_until_idle(10.0);
    ASSERT_TRUE(bench.host().done()) << bench.host().tail(10);
    const TimingProfiler& p = *bench.mcu().profile();
    ASSERT_EQ(p.vectors().count(11), 1u);
    ASSERT_EQ(p.vectors().count(16), 1u);
    const VectorProfile& step = p.vectors().at(11);
    const VectorProfile& pulse_end = p.vectors().at(16);
    EXPECT_GE(step.runs, 1600u);  // one per step (README: the first run only writes OCR1A)
    EXPECT_EQ(pulse_end.max_depth, 2);
    // The nested overflow's cycles count in the step vector's inclusive time
    // and not in its exclusive time.
    EXPECT_GT(step.inclusive_cycles.max(), step.exclusive_cycles.max());
    EXPECT_GE(step.inclusive_cycles.max() - step.exclusive_cycles.max(), pulse_end.inclusive_cycles.min());
}

}  // namespace
}  // namespace avrbench
