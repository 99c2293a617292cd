// The timing profile of one MCU's run, seen from every cycle without
// instrumenting the firmware (what SEGGER SystemView or Tracealyzer get
// from instrumented firmware on hardware):
//  - per interrupt vector: how often it ran, its execution time from the
//    vector's first instruction to the end of its RETI (inclusive of
//    interrupts nested in it, and exclusive of them), its latency from the
//    flag being raised with the interrupt enabled (or from the enable, when
//    the flag was already set) to the vector's first instruction, and how
//    deep the nesting went (an ISR that re-enables interrupts can nest in
//    itself);
//  - the longest stretch with interrupts disabled, from the end of the
//    instruction that cleared I (or the vector's first instruction: the
//    hardware clears I on entry) to the end of the one that set it, with
//    where it began;
//  - CPU load: cycles executing, sleeping, and jumped over by the idle-loop
//    skipper (mcu/IdleLoopSkip.hpp);
//  - the stack's high-water mark: the lowest SP, its headroom above the end
//    of .data/.bss/.noinit, and the instruction that reached it.
//
// Collected by Mcu::enable_profile: the run loop then takes its general
// step for every instruction (no fast path), so a profiled run is slower;
// the numbers are the same for the same inputs (simulated time only).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/Time.hpp"

extern "C" {
#include <sim_avr.h>
}

namespace avrbench {

class Mcu;

// Exact order statistics of a set of cycle counts (a histogram: memory
// grows with the distinct values, not with the samples).
class CycleStats {
public:
    void add(Cycle value);
    std::uint64_t count() const { return count_; }
    Cycle min() const { return histogram_.empty() ? 0 : histogram_.begin()->first; }
    Cycle max() const { return histogram_.empty() ? 0 : histogram_.rbegin()->first; }
    // The smallest value with at least `fraction` of the samples at or below it.
    Cycle quantile(double fraction) const;
    Cycle median() const { return quantile(0.5); }
    Cycle p99() const { return quantile(0.99); }

private:
    std::map<Cycle, std::uint64_t> histogram_;
    std::uint64_t count_ = 0;
};

struct VectorProfile {
    int vector = 0;
    std::uint64_t runs = 0;
    CycleStats inclusive_cycles, exclusive_cycles, latency_cycles;
    int max_depth = 0;  // 1: never nested in another ISR
};

class TimingProfiler {
public:
    explicit TimingProfiler(Mcu& mcu);
    ~TimingProfiler();
    TimingProfiler(const TimingProfiler&) = delete;
    TimingProfiler& operator=(const TimingProfiler&) = delete;

    // Called by the run loop after every step (instruction, interrupt entry
    // or sleep jump), with the cycle and state before it.
    void after_step(Cycle cycle_before, bool was_sleeping, std::uint32_t pc_before);
    // A reset drops the ISRs in progress.
    void reset();

    const std::map<int, VectorProfile>& vectors() const { return vectors_; }
    Cycle active_cycles() const { return active_; }
    Cycle sleeping_cycles() const { return sleeping_; }
    std::uint16_t lowest_sp() const { return lowest_sp_; }
    std::uint32_t lowest_sp_pc() const { return lowest_sp_pc_; }
    Cycle lowest_sp_cycle() const { return lowest_sp_cycle_; }
    Cycle longest_interrupts_off() const { return longest_off_; }
    Cycle longest_off_start() const { return longest_off_start_; }
    std::uint32_t longest_off_pc() const { return longest_off_pc_; }
    // The vector whose entry began the longest stretch; -1: a CLI or SREG
    // write at longest_off_pc(). The stretch from the reset to the
    // firmware's first SEI is not one of them: it is first_sei_cycle().
    int longest_off_vector() const { return longest_off_vector_; }
    // When interrupts were first enabled (~0: never).
    Cycle first_sei_cycle() const { return first_sei_; }

    // Lines for the run summary and the profile as JSON (docs/CLI.md "--profile").
    std::vector<std::string> summary_lines() const;
    std::string json() const;

private:
    static void on_pending(avr_irq_t* irq, std::uint32_t value, void* param);
    static void on_running(avr_irq_t* irq, std::uint32_t value, void* param);
    struct Hook {
        TimingProfiler* self;
        avr_int_vector_t* vector;
    };
    struct Active {
        int vector;
        Cycle entry;        // the vector's first instruction (set at the end of the step that served it)
        Cycle raised;       // when its flag was raised (~0: not seen)
        Cycle nested = 0;  // cycles of ISRs nested in this one
    };

    Mcu& mcu_;
    avr_t* avr_;
    std::vector<Hook> hooks_;                 // one per vector (stable: reserved up front)
    std::map<int, Cycle> pending_since_;      // vector -> cycle its flag was raised
    std::vector<Active> stack_;               // ISRs in progress, innermost last
    std::map<int, VectorProfile> vectors_;
    int entered_vector_ = -1;                 // a vector entered during the present step
    int reti_pending_ = 0;                    // RETIs seen during the present step
    Cycle active_ = 0, sleeping_ = 0;
    std::uint16_t lowest_sp_ = 0xFFFF;
    std::uint32_t lowest_sp_pc_ = 0;
    Cycle lowest_sp_cycle_ = 0;
    bool interrupts_on_ = false;
    Cycle off_since_ = 0;
    std::uint32_t off_pc_ = 0;
    int off_vector_ = -2;
    Cycle longest_off_ = 0, longest_off_start_ = 0;
    Cycle first_sei_ = ~Cycle{0};
    std::uint32_t longest_off_pc_ = 0;
    int longest_off_vector_ = -1;
};

}  // namespace avrbench
