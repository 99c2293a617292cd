// Helpers for the timer conformance tests (tests/conformance_timers): load a
// firmware from firmware/conformance/timers, log a pin's edges, turn edges into
// intervals and pulse widths.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

extern "C" {
#include <sim_avr.h>
}

#include "core/ElfImage.hpp"
#include "core/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench::test::timers {

// The three parts the timer firmware is built for, by ELF name suffix.
struct TimerPart {
    const char* suffix;  // "" (ATmega328P), "_m2560", "_m32"
    const char* mcu;     // what Mcu::mcu_type() reports
};
inline constexpr TimerPart kAtmega328p{"", "atmega328p"};
inline constexpr TimerPart kAtmega2560{"_m2560", "atmega2560"};
inline constexpr TimerPart kAtmega32{"_m32", "atmega32"};

inline ElfImage timer_firmware(const std::string& name, const TimerPart& part) {
    return ElfImage::load(firmware(name + part.suffix));
}

// `count` consecutive bytes / little-endian words of a RAM array by its symbol.
inline std::vector<unsigned> ram_bytes(const Mcu& mcu, const std::string& symbol, unsigned count) {
    const std::vector<std::uint8_t> bytes = mcu.read_ram(symbol, count);  // throws for a symbol not in RAM
    return std::vector<unsigned>(bytes.begin(), bytes.end());
}
inline std::vector<unsigned> ram_words(const Mcu& mcu, const std::string& symbol, unsigned count) {
    const auto bytes = ram_bytes(mcu, symbol, 2 * count);
    std::vector<unsigned> out;
    for (std::size_t i = 0; i + 1 < bytes.size(); i += 2) out.push_back(bytes[i] | (bytes[i + 1] << 8));
    return out;
}

// Every level change of one pin from the moment the log is made: the cycle
// the bench stamps it with and the new level.
class PinLog {
public:
    struct Edge {
        Cycle cycle;
        bool level;
    };

    PinLog(Mcu& mcu, const std::string& pin) : initial_(mcu.pin(pin).level()) {
        mcu.pin(pin).on_change([this](Cycle cycle, bool level) { edges_.push_back({cycle, level}); });
    }
    PinLog(const PinLog&) = delete;
    PinLog& operator=(const PinLog&) = delete;

    bool initial() const { return initial_; }
    const std::vector<Edge>& edges() const { return edges_; }
    std::vector<Cycle> cycles() const {
        std::vector<Cycle> out;
        for (const auto& e : edges_) out.push_back(e.cycle);
        return out;
    }
    std::vector<Cycle> rises() const { return filtered(true); }
    std::vector<Cycle> falls() const { return filtered(false); }
    // Cycles between consecutive edges (any direction).
    std::vector<Cycle> intervals() const { return differences(cycles()); }
    // For every rising edge followed by a falling one: how long the pin was high.
    std::vector<Cycle> high_times() const { return widths(true); }
    std::vector<Cycle> low_times() const { return widths(false); }

    static std::vector<Cycle> differences(const std::vector<Cycle>& v) {
        std::vector<Cycle> out;
        for (std::size_t i = 1; i < v.size(); ++i) out.push_back(v[i] - v[i - 1]);
        return out;
    }

private:
    std::vector<Cycle> filtered(bool level) const {
        std::vector<Cycle> out;
        for (const auto& e : edges_) {
            if (e.level == level) out.push_back(e.cycle);
        }
        return out;
    }
    std::vector<Cycle> widths(bool level) const {
        std::vector<Cycle> out;
        for (std::size_t i = 1; i < edges_.size(); ++i) {
            if (edges_[i - 1].level == level && edges_[i].level != level) out.push_back(edges_[i].cycle - edges_[i - 1].cycle);
        }
        return out;
    }

    bool initial_;
    std::vector<Edge> edges_;
};

// All values of `v` equal `expected` (and there are at least `min_count`).
inline ::testing::AssertionResult all_equal(const std::vector<Cycle>& v, Cycle expected, std::size_t min_count) {
    if (v.size() < min_count) {
        return ::testing::AssertionFailure() << "only " << v.size() << " values, expected at least " << min_count;
    }
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (v[i] != expected) {
            ::testing::AssertionResult r = ::testing::AssertionFailure();
            r << "value " << i << " is " << v[i] << ", expected " << expected << "; all:";
            for (std::size_t k = 0; k < v.size() && k < 24; ++k) r << ' ' << v[k];
            return r;
        }
    }
    return ::testing::AssertionSuccess();
}

}  // namespace avrbench::test::timers
