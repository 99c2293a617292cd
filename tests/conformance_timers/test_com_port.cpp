// The OC1A pin against PORT and DDR, and FOC1A (firmware/conformance/timers/tmr_com_port).
//
// ATmega328P datasheet §16.8 "Compare Match Output Unit" (ATmega2560 §17.8,
// ATmega32 "Compare Match Output Unit"): "The general I/O port function is
// overridden by the Output Compare (OC1x) from the Waveform Generator if either
// of the COM1x1:0 bits are set. However, the OC1x pin direction (input or
// output) is still controlled by the Data Direction Register (DDR) for the
// port pin. The Data Direction Register bit for the OC1x pin (DDR_OC1x) must be
// set as output before the OC1x value is visible on the pin." PORT keeps the
// firmware's value and shows again once COM1x1:0 = 0. §16.7.1: a FOC1x strobe
// updates OC1x "as if a real Compare Match had occurred" and does not set OCF1x.
// Timer1 runs CTC at clk/1 with OCR1A = 99: a toggle every 100 cycles.
#include "conformance_timers/TimerTestSupport.hpp"

namespace avrbench::test::timers {
namespace {

std::vector<PinLog::Edge> between(const PinLog& log, Cycle from, Cycle to) {
    std::vector<PinLog::Edge> out;
    for (const auto& e : log.edges()) {
        if (e.cycle > from && e.cycle < to) out.push_back(e);
    }
    return out;
}

void expect_override(const TimerPart& part, const char* oc1a, const char* marker0, const char* marker1) {
    Mcu mcu(timer_firmware("tmr_com_port", part));
    PinLog pin(mcu, oc1a);
    PinLog phase(mcu, marker0);
    PinLog strobe(mcu, marker1);
    mcu.run_for(12000);
    ASSERT_EQ(mcu.read_ram_u8("done"), 1);
    const auto m = phase.cycles();  // m[k]: start of phase k + 1
    ASSERT_EQ(m.size(), 6u);

    // Phases 1 and 2: toggles every 100 cycles throughout, whatever the
    // firmware writes to the port register (other bits in phase 1, the OC1A
    // bit itself in phase 2); PORT reads back the firmware's value, PIN the pin.
    const auto p12 = between(pin, m[0], m[2]);
    ASSERT_GE(p12.size(), 20u);
    for (std::size_t i = 1; i < p12.size(); ++i) EXPECT_EQ(p12[i].cycle - p12[i - 1].cycle, 100u) << "edge " << i;
    EXPECT_EQ(mcu.read_ram_u8("port_or"), 0) << "the OC1A bit of PORT changed with OC1A";
    EXPECT_EQ(mcu.read_ram_u8("pin_seen"), 3) << "PIN did not follow OC1A";
    EXPECT_EQ(mcu.read_ram_u8("port_p2"), 1);

    // Phase 3: COM1A = 00: the pin shows PORT = 1 (one edge at most, to high).
    const auto p3 = between(pin, m[2], m[3]);
    EXPECT_LE(p3.size(), 1u);
    if (!p3.empty()) {
        EXPECT_TRUE(p3[0].level);
    }
    // Phase 4: COM1A = 01 but DDR = 0: an input pulled up by PORT = 1, no OC1A.
    EXPECT_TRUE(between(pin, m[3], m[4]).empty());
    EXPECT_EQ(mcu.read_ram_u8("pin_p4"), 2) << "PIN read 0 while the pin is pulled up";
    // Phase 5: DDR = 1: OC1A visible again, on the same 100-cycle grid (the
    // timer never stopped); the first edge may be the DDR write itself.
    const auto p5 = between(pin, m[4], m[5]);
    ASSERT_GE(p5.size(), 8u);
    for (std::size_t i = 1; i < p5.size(); ++i) EXPECT_EQ((p5[i].cycle - p12[0].cycle) % 100, 0u) << "edge " << i;

    // Phase 6: timer stopped; FOC1A with COM1A = 11 sets OC1A at once, with
    // COM1A = 10 clears it at once: each edge within the COM1A and FOC1A
    // writes after the marker (two STS/OUT, at most 6 cycles); no OCF1A.
    const auto k = strobe.cycles();
    ASSERT_EQ(k.size(), 2u);
    const auto rise = between(pin, k[0], k[1]);
    ASSERT_EQ(rise.size(), 1u);
    EXPECT_TRUE(rise[0].level);
    EXPECT_LE(rise[0].cycle - k[0], 6u);
    const auto fall = between(pin, k[1], mcu.cycle() + 1);
    ASSERT_EQ(fall.size(), 1u);
    EXPECT_FALSE(fall[0].level);
    EXPECT_LE(fall[0].cycle - k[1], 6u);
    EXPECT_EQ(mcu.read_ram_u8("ocf_p6"), 0);
}

TEST(TimerCompareOutput, OverridesThePinNotThePortRegisterAtmega328p) { expect_override(kAtmega328p, "PB1", "PC0", "PC1"); }
TEST(TimerCompareOutput, OverridesThePinNotThePortRegisterAtmega2560) { expect_override(kAtmega2560, "PB5", "PF0", "PF1"); }
TEST(TimerCompareOutput, OverridesThePinNotThePortRegisterAtmega32) { expect_override(kAtmega32, "PD5", "PC0", "PC1"); }

}  // namespace
}  // namespace avrbench::test::timers
