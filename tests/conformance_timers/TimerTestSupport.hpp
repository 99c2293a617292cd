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

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "support/McuSuffix.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"

namespace avrbench::test::timers {

// The three parts the timer firmware is built for.
struct TimerPart {
    const char* mcu;  // what Mcu::mcu_type() reports
};
inline constexpr TimerPart kAtmega328p{"atmega328p"};
inline constexpr TimerPart kAtmega2560{"atmega2560"};
inline constexpr TimerPart kAtmega32{"atmega32"};

inline ElfImage timer_firmware(const std::string& name, const TimerPart& part) {
    return ElfImage::load(firmware(name + firmware_suffix(part.mcu)));
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

using test::PinLog;

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
