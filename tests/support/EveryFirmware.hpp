// Every firmware the build makes, run with every pin and USART0 traced: for
// the tests that compare two ways of running the same program (run loops,
// idle skipping, timer replay, periodic waves) and must end in the same
// state with the same timeline.
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

extern "C" {
#include <sim_avr.h>
}

#include "mcu/ElfImage.hpp"
#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"
#include "trace/Recorder.hpp"
#include "trace/Timeline.hpp"

namespace avrbench::test {

// Names (without .elf) of every ELF in the build's firmware folder, sorted.
inline std::vector<std::string> all_firmware() {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(::avrbench::test::firmware_dir())) {
        if (entry.path().extension() == ".elf") names.push_back(entry.path().stem().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

// Arduino sketches and other ELFs without .mmcu: the board they were built for.
inline void set_board_mcu(const std::string& name, const ElfImage& elf, McuOptions& options) {
    if (!elf.embedded_mcu().empty()) return;
    options.mcu_type = name.find("mega") != std::string::npos ? "atmega2560" : "atmega328p";
    options.frequency_hz = 16'000'000;
}

struct TracedEnd {
    Cycle cycle = 0;
    std::uint32_t pc = 0;
    std::vector<std::uint8_t> data;  // registers, I/O, RAM
    std::vector<TimelineEvent> events;
    std::vector<std::string> findings;
    std::uint64_t steps = 0;
    std::uint64_t idle_jumps = 0;
};

// 20 ms of `name` with every pin and USART0 traced and a few serial lines,
// so that receiver interrupts are in the mix.
inline TracedEnd run_traced(const std::string& name, McuOptions options) {
    const ElfImage elf = ElfImage::load(firmware(name));
    set_board_mcu(name, elf, options);
    Mcu mcu(elf, options);
    Timeline timeline;
    Recorder recorder(timeline);
    recorder.trace_pins(mcu, "all");
    try {
        recorder.trace_uart_tx(mcu, mcu.uart(0));
        mcu.uart(0).send("G1 X1\n?\nM105\nhello\n");
    } catch (const BadInput&) {
        // an MCU without USART0
    }
    mcu.run_until(mcu.frequency_hz() / 50);
    TracedEnd s;
    s.cycle = mcu.cycle();
    s.pc = mcu.pc_bytes();
    s.data = mcu.data_memory();
    s.events = timeline.events();
    for (const auto& f : mcu.findings()) s.findings.push_back(f.describe());
    s.steps = mcu.steps();
    s.idle_jumps = mcu.idle_jumps();
    return s;
}

inline void expect_same_end(const TracedEnd& a, const TracedEnd& b, const std::string& name) {
    EXPECT_EQ(a.cycle, b.cycle) << name;
    EXPECT_EQ(a.pc, b.pc) << name;
    EXPECT_TRUE(a.data == b.data) << name << ": registers, I/O or RAM differ";
    EXPECT_EQ(a.findings, b.findings) << name;
    ASSERT_EQ(a.events.size(), b.events.size()) << name;
    for (std::size_t i = 0; i < a.events.size(); ++i) {
        const bool same = a.events[i].cycle == b.events[i].cycle && a.events[i].signal == b.events[i].signal &&
                          a.events[i].value.bits == b.events[i].value.bits;
        ASSERT_TRUE(same) << name << ": event " << i << " differs";
    }
}

}  // namespace avrbench::test
