// The timer model's replay of a steady period (core/fixes/TimerModel.cpp:
// events taken from a record of one period instead of computed) against the
// model computing every event: every firmware the build makes runs 20 ms
// both ways, with every pin and USART0 traced and a few lines of serial
// input, and must end in the same state (cycle, PC, registers, I/O, RAM,
// steps) with the same timeline and findings. Skipping idle loops and
// periodic waves stay on, as the CLI runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

extern "C" {
#include <sim_avr.h>
}

#include "core/Errors.hpp"
#include "core/Mcu.hpp"
#include "core/fixes/Fixes.hpp"
#include "support/Paths.hpp"
#include "trace/Recorder.hpp"
#include "trace/Timeline.hpp"

namespace avrbench {
namespace {

struct EndState {
    Cycle cycle = 0;
    std::uint32_t pc = 0;
    std::vector<std::uint8_t> data;
    std::vector<TimelineEvent> events;
    std::vector<std::string> findings;
    std::uint64_t steps = 0;
};

// Restores replay (the default) however the test ends.
struct ReplaySetting {
    explicit ReplaySetting(bool on) { set_timer_replay(on); }
    ~ReplaySetting() { set_timer_replay(true); }
};

EndState run(const std::string& name, bool replay, Cycle cycles) {
    const ReplaySetting setting(replay);
    McuOptions options;
    const ElfImage elf = ElfImage::load(test::firmware(name));
    if (elf.embedded_mcu().empty()) {
        options.mcu_type = name.find("mega") != std::string::npos ? "atmega2560" : "atmega328p";
        options.frequency_hz = 16'000'000;
    }
    Mcu mcu(elf, options);
    Timeline timeline;
    Recorder recorder(timeline);
    recorder.trace_pins(mcu, "all");
    try {
        recorder.trace_uart_tx(mcu, mcu.uart(0));
        mcu.uart(0).send("G1 X1\n?\nM105\nM42 P10 S64\nhello\n");
    } catch (const BadInput&) {
        // an MCU without USART0
    }
    mcu.run_until(cycles);
    EndState s;
    s.cycle = mcu.cycle();
    s.pc = mcu.pc_bytes();
    const avr_t* avr = mcu.avr();
    s.data.assign(avr->data, avr->data + avr->ramend + 1);
    s.events = timeline.events();
    for (const auto& f : mcu.findings()) s.findings.push_back(f.describe());
    s.steps = mcu.steps();
    return s;
}

std::vector<std::string> all_firmware() {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(AVRBENCH_FIRMWARE_DIR)) {
        if (entry.path().extension() == ".elf") names.push_back(entry.path().stem().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

TEST(TimerReplay, EndsWhereTheModelComputingEveryEventEndsOnEveryFirmware) {
    const auto names = all_firmware();
    ASSERT_GT(names.size(), 100u);
    for (const auto& name : names) {
        const Cycle cycles = 16'000'000 / 50;  // 20 ms at 16 MHz
        const EndState a = run(name, false, cycles), b = run(name, true, cycles);
        EXPECT_EQ(a.cycle, b.cycle) << name;
        EXPECT_EQ(a.pc, b.pc) << name;
        EXPECT_TRUE(a.data == b.data) << name << ": registers, I/O or RAM differ";
        EXPECT_EQ(a.findings, b.findings) << name;
        EXPECT_EQ(a.steps, b.steps) << name;
        ASSERT_EQ(a.events.size(), b.events.size()) << name;
        for (std::size_t i = 0; i < a.events.size(); ++i) {
            const bool same = a.events[i].cycle == b.events[i].cycle && a.events[i].signal == b.events[i].signal &&
                              a.events[i].value.bits == b.events[i].value.bits;
            ASSERT_TRUE(same) << name << ": event " << i << " of " << a.events.size() << " differs";
        }
    }
}

}  // namespace
}  // namespace avrbench
