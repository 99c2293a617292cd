// Shared helpers of the peripheral conformance tests: the three parts, and
// marker pins whose edges are stamped with the cycle of the writing instruction.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "support/McuSuffix.hpp"
#include "support/Paths.hpp"
#include "support/PinLog.hpp"

namespace avrbench::test {

struct Part {
    const char* mcu;       // what Mcu::mcu_type() reports
    const char* name;      // for test output
    Cycle response;        // interrupt response: §7.7.1 (328P, m32) 4 cycles; 2560 §7.8.1: 5
    Cycle reti;            // RETI: 4 cycles; 5 on the 2560 (same sections)
    const char* int0_pin;  // 328P/m32: PD2; 2560: PD0 (2560 §15 / pinout)
    const char* int1_pin;  // 328P/m32: PD3; 2560: PD1
    std::uint8_t intf0;    // INTF0 in EIFR (328P §13.2.3, 2560 §15.2.4): bit 0; in GIFR (m32): bit 6
    std::uint8_t intf1;    // INTF1: bit 1; m32: bit 7
    // INT0 edges wake the part from Power-down: only where INT0 is
    // asynchronous (2560 §15: INT3:0); on the 328P and the m32 INT0/INT1
    // edges need clk_IO (328P §10.1 Table 10-1 note 3).
    bool int0_edge_wakes_power_down;
};

inline const Part kAtmega328p{"atmega328p", "ATmega328P", 4, 4, "PD2", "PD3", 0x01, 0x02, false};
inline const Part kAtmega2560{"atmega2560", "ATmega2560", 5, 5, "PD0", "PD1", 0x01, 0x02, true};
inline const Part kAtmega32{"atmega32", "ATmega32", 4, 4, "PD2", "PD3", 0x40, 0x80, false};

// Every JMP in the vector table takes 3 cycles (AVR Instruction Set Manual; §7.7.1).
constexpr Cycle kJmp = 3;
// SBI/CBI take 2 cycles, INC/NOP/SLEEP 1, RJMP 2 (AVR Instruction Set Manual).
constexpr Cycle kSbi = 2;

// Parameterised test names: the part.
inline std::string part_name(const ::testing::TestParamInfo<const Part*>& info) { return info.param->name; }

inline Mcu load(const std::string& firmware, const Part& part) {
    return Mcu(ElfImage::load(test::firmware(firmware + firmware_suffix(part.mcu))));
}

// Rising and falling edges of the eight pins of a port (PORTB by default), by bit.
class Markers {
public:
    Markers(Mcu& mcu, const char* port = "PB") {
        for (int bit = 0; bit < 8; ++bit) {
            logs_[bit] = std::make_unique<PinLog>(mcu, std::string(port) + static_cast<char>('0' + bit));
        }
    }
    const std::vector<Cycle>& rises(int bit) const { return logs_[bit]->rises(); }
    const std::vector<Cycle>& falls(int bit) const { return logs_[bit]->falls(); }
    Cycle rise(int bit, std::size_t n = 0) const {
        EXPECT_GT(rises(bit).size(), n) << "marker bit " << bit << " did not rise " << n + 1 << " time(s)";
        return rises(bit).size() > n ? rises(bit)[n] : 0;
    }
    Cycle fall(int bit, std::size_t n = 0) const {
        EXPECT_GT(falls(bit).size(), n) << "marker bit " << bit << " did not fall " << n + 1 << " time(s)";
        return falls(bit).size() > n ? falls(bit)[n] : 0;
    }

private:
    std::array<std::unique_ptr<PinLog>, 8> logs_;
};

// Runs until `bit` of the markers has risen (or `limit` cycles passed).
inline bool run_until_rise(Mcu& mcu, const Markers& m, int bit, Cycle limit = 2'000'000) {
    const Cycle end = mcu.cycle() + limit;
    while (m.rises(bit).empty() && mcu.cycle() < end && !mcu.halted()) mcu.run_for(50);
    return !m.rises(bit).empty();
}

}  // namespace avrbench::test
