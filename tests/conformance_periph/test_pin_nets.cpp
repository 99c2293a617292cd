// Pins read what their nets resolve to (firmware/conformance/peripherals/
// pin_nets; wiring/Drive.hpp): the MCU's pull-up against board resistors,
// wired-AND sharing of an open-drain net, PUD, a floating divider and an output
// fighting a tie. Expected levels: R_PU 20-50 kohm and V_IL <= 0.3 VCC,
// V_IH >= 0.6 VCC (ATmega328P §28.2, 2560 §31.2, ATmega32 §28), worked out by
// hand beside each case; with R_PU anywhere in 20-50 kohm the answers are the
// same (the bench uses 35 kohm).
#include <gtest/gtest.h>

#include <string>

#include "wiring/Net.hpp"
#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "support/Paths.hpp"
#include "wiring/Drive.hpp"

namespace avrbench {
namespace {

std::string board_text(const std::string& mcu_type) {
    return "mcus:\n  m: {type: " + mcu_type + R"(, clock: 16MHz}
parts:
  down_1k: {type: pull_resistor, to: gnd, resistance: 1kohm}
  down_100k: {type: pull_resistor, to: gnd, resistance: 100kohm}
  down_47k: {type: pull_resistor, to: gnd, resistance: 47kohm}
  up_4k7: {type: pull_resistor, to: vcc, resistance: 4.7kohm}
  tie_gnd: {type: pull_resistor, to: gnd, resistance: 0ohm}
nets:
  divider_1k: [m.PB0, down_1k.pin]
  divider_100k: [m.PB1, down_100k.pin]
  divider_47k: [m.PB2, down_47k.pin]
  open_drain: [m.PB3, m.PB4, up_4k7.pin]
  fight: [m.PB5, tie_gnd.pin]
)";
}

void expect_nets_resolve(const std::string& mcu_type, const std::string& firmware) {
    const std::uint64_t counted_before = findings_recorded();
    Board board(parse_board_text(board_text(mcu_type), "pin-nets.yaml"), {{"m", test::firmware(firmware)}});
    board.run_for_seconds(0.001);
    Mcu& m = board.mcu("m");
    ASSERT_EQ(m.read_ram_u8("done"), 1) << firmware;
    const auto reads = m.read_ram("reads", 8);
    // 35k up / 1k down: 1/35 / (1/35 + 1/1) = 0.028 VCC (20k: 0.048) <= 0.3 -> 0
    EXPECT_EQ(reads[0], 0) << firmware << ": 1 kohm pull-down against the pull-up";
    // 35k up / 100k down: 100 / 135 = 0.74 VCC (50k: 0.67) >= 0.6 -> 1
    EXPECT_EQ(reads[1], 1) << firmware << ": 100 kohm pull-down against the pull-up";
    // 35k up / 47k down: 47 / 82 = 0.57 VCC (between 0.3 and 0.6) -> floating, reads 0
    EXPECT_EQ(reads[2], 0) << firmware << ": 47 kohm divider is neither level";
    EXPECT_EQ(reads[3], 0) << firmware << ": PUD leaves only the 100 kohm pull-down";
    EXPECT_EQ(reads[4], 1) << firmware << ": released open-drain net, 4.7 kohm pull-up";
    EXPECT_EQ(reads[5], 0) << firmware << ": PB3 pulls the shared net low";
    EXPECT_EQ(reads[6], 0) << firmware << ": PB3 reads PB4's low";
    EXPECT_EQ(reads[7], 1) << firmware << ": both let go";

    int floating = 0, contention = 0;
    for (const Finding& f : board.findings()) {
        if (f.kind == Net::kFloatingInputRead) {
            ++floating;
            EXPECT_EQ(f.source, "divider_47k");
            // The PC of the instruction that read PINB, in the firmware's read_pin_b().
            EXPECT_NE(f.symbol.find("read_pin_b"), std::string::npos) << f.describe();
            EXPECT_NE(f.detail.find("0.57 VCC"), std::string::npos) << f.detail;
        }
        if (f.kind == Net::kNetContention) {
            ++contention;
            EXPECT_EQ(f.source, "fight");
            EXPECT_NE(f.detail.find("m.PB5 high"), std::string::npos) << f.detail;
            EXPECT_NE(f.detail.find("tie_gnd.pin low"), std::string::npos) << f.detail;
        }
    }
    // One read of the floating net: one finding. The nets with a pull resistor
    // that gives a valid level are not floating, and PB3/PB4's net never floats.
    EXPECT_EQ(floating, 1) << firmware;
    EXPECT_EQ(contention, 1) << firmware;
    // Each counted once where a debugger's --break-at-finding looks
    // (wiring/Net.cpp counted a contention twice until 2026-12-02).
    EXPECT_EQ(findings_recorded() - counted_before, board.findings().size()) << firmware;
    EXPECT_EQ(board.nets()[4]->resolution().state, NetState::Contention);
}

TEST(PinNets, ResolveElectricallyAtmega328p) { expect_nets_resolve("atmega328p", "pin_nets"); }
TEST(PinNets, ResolveElectricallyAtmega2560) { expect_nets_resolve("atmega2560", "pin_nets_m2560"); }
TEST(PinNets, ResolveElectricallyAtmega32) { expect_nets_resolve("atmega32", "pin_nets_m32"); }

// The resolution rules themselves, with the thresholds' edges.
TEST(NetResolution, StrongDriversWinAndFightEachOther) {
    const Drive pull_up = Drive::weak(true, 10e3);
    EXPECT_EQ(resolve(std::vector<Drive>{pull_up, Drive::strong(false)}).level, false);
    EXPECT_EQ(resolve(std::vector<Drive>{pull_up, Drive::strong(false)}).state, NetState::Driven);
    EXPECT_EQ(resolve(std::vector<Drive>{Drive::strong(true), Drive::strong(false)}).state, NetState::Contention);
    EXPECT_EQ(resolve(std::vector<Drive>{Drive::strong(true), Drive::strong(true)}).state, NetState::Driven);
    EXPECT_EQ(resolve(std::vector<Drive>{Drive::none(), Drive::none()}).state, NetState::Floating);
    EXPECT_EQ(resolve(std::vector<Drive>{}).state, NetState::Floating);
}

TEST(NetResolution, DividerReadAgainstVilAndVih) {
    // Equal resistors: 0.5 VCC, neither V_IL max (0.3) nor V_IH min (0.6).
    auto r = resolve(std::vector<Drive>{Drive::weak(true, 10e3), Drive::weak(false, 10e3)});
    EXPECT_EQ(r.state, NetState::Floating);
    EXPECT_NEAR(r.volts_fraction, 0.5, 1e-12);
    // 10k up, 15k down: 15/25 = 0.6 VCC exactly: V_IH min, reads 1.
    r = resolve(std::vector<Drive>{Drive::weak(true, 10e3), Drive::weak(false, 15e3)});
    EXPECT_EQ(r.state, NetState::Driven);
    EXPECT_TRUE(r.level);
    // 70k up, 30k down: 0.3 VCC exactly: V_IL max, reads 0.
    r = resolve(std::vector<Drive>{Drive::weak(true, 70e3), Drive::weak(false, 30e3)});
    EXPECT_EQ(r.state, NetState::Driven);
    EXPECT_FALSE(r.level);
}

}  // namespace
}  // namespace avrbench
