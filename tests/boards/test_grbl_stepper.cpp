// A grbl-style step generator end to end (firmware/boards/grbl_stepper:
// ATmega328P 16 MHz, UNO + CNC shield; X/Y/Z STEP PD2/PD3/PD4, DIR PD5/PD6/PD7,
// enable PB0 active low, limits PB1/PB2/PB4).
//
// The firmware's arithmetic (see its main.c):
//  - a move runs at the rate of its longest axis: steps/s = $11x * $10x / 60,
//    one step event every floor(16e6 / steps_per_s) cycles; defaults $100 = 80
//    steps/mm, $110 = 6000 mm/min: 8000 steps/s, 2000 cycles;
//  - Timer1 CTC at clk/1 is the step clock: OCR1A = period - 1, so compare
//    matches come exactly `period` cycles apart (ATmega328P §16.9.2); the
//    vector writes the STEP bits at a fixed offset from its entry, so the
//    rising edges are `period` apart up to the interrupt response jitter: "If
//    an interrupt occurs during execution of a multi-cycle instruction, this
//    instruction is completed before the interrupt is served" (§7.7.1); the
//    main loop during a move is LDS/AND/BRNE (at most 2 cycles): +-1 cycle;
//  - the first move's first vector run happens while OCR1A is still 0 (its
//    reset value) at clk/1: OCF1A is set on every cycle (§16.9.2 with
//    OCR1A = 0), so enabling OCIE1A runs the vector at once (§7.7).
#include <algorithm>

extern "C" {
#include <avr_eeprom.h>
#include <sim_io.h>
}

#include "conformance_timers/TimerTestSupport.hpp"
#include "periph/usart/Uart.hpp"

namespace avrbench::test::timers {
namespace {

constexpr Cycle kDefaultPeriod = 16000000 / (6000 * 80 / 60);  // 2000 cycles per step

// Pulse width, hand-calculated from the datasheet and grbl_stepper.lst
// (avr-gcc 5.4 -Os), for a pulse of $0 = p us (Timer0 reload 256 - 2p, clk/8):
//  - the step vector writes PORTD (STEP high) at cycle s; its `out TCCR0B`
//    starts Timer0 7 cycles later (out, and, breq, lds, out, ldi: 1+1+1+2+1+1);
//  - Timer0 overflows on its (2p)-th clock; the first clock of a prescaled
//    timer comes 1 to N cycles after it starts (§17.1, N = 8: the prescaler
//    runs free), so the overflow is 7 + [1, 8] + (2p - 1) * 8 cycles after s;
//  - the overflow vector then waits for the instruction in progress (0 to 3
//    more cycles in the step vector's code), takes the 4-cycle interrupt
//    response (§7.7.1), the vector's JMP (3) and its prologue up to the PORTD
//    write (push r1, push r0, in, push r0, eor, push r24, push r25, in, andi:
//    2+2+1+2+1+2+2+1+1 = 14): 21 to 24 cycles.
// 10 us: [7 + 1 + 152 + 21, 7 + 8 + 152 + 24] = [181, 191].
struct Bounds {
    Cycle min, max;
};
constexpr Bounds pulse_bounds(unsigned pulse_us) {
    const Cycle clocks = 2 * pulse_us;
    return {7 + 1 + (clocks - 1) * 8 + 21, 7 + 8 + (clocks - 1) * 8 + 24};
}

class Grbl {
public:
    Grbl() : mcu_(timer_firmware("grbl_stepper", kAtmega328p)), uart_(mcu_.uart(0)) {
        for (const char* p : {"PD2", "PD3", "PD4", "PD5", "PD6", "PD7", "PB0"}) logs_.push_back(std::make_unique<PinLog>(mcu_, p));
        // Boot: settings from EEPROM (defaults written on the first boot), banner.
        run_until_reply("]\r\n", 3'000'000);
    }

    // Sends one line and runs until its answer (ok / error / ALARM) or `limit` cycles.
    std::string command(const std::string& text, Cycle limit = 8'000'000) {
        const std::size_t before = uart_.transmitted_text().size();
        uart_.send(text + "\n");
        const Cycle end = mcu_.cycle() + limit;
        while (mcu_.cycle() < end) {
            mcu_.run_for(20000);
            const std::string out = uart_.transmitted_text().substr(before);
            for (const char* answer : {"ok\r\n", "error:", "ALARM:"}) {
                const auto at = out.find(answer);
                if (at != std::string::npos && out.find("\r\n", at) != std::string::npos) return out;
            }
        }
        return uart_.transmitted_text().substr(before);
    }

    void run_until_reply(const std::string& text, Cycle limit) {
        const Cycle end = mcu_.cycle() + limit;
        while (mcu_.cycle() < end && uart_.transmitted_text().find(text) == std::string::npos) mcu_.run_for(20000);
        ASSERT_NE(uart_.transmitted_text().find(text), std::string::npos) << uart_.transmitted_text();
    }

    const PinLog& step(int axis) const { return *logs_[static_cast<std::size_t>(axis)]; }
    const PinLog& dir(int axis) const { return *logs_[static_cast<std::size_t>(3 + axis)]; }
    const PinLog& enable() const { return *logs_[6]; }
    Mcu& mcu() { return mcu_; }

private:
    Mcu mcu_;
    Uart& uart_;
    std::vector<std::unique_ptr<PinLog>> logs_;
};

std::vector<Cycle> rises_after(const PinLog& log, Cycle from) {
    std::vector<Cycle> out;
    for (Cycle c : log.rises()) {
        if (c >= from) out.push_back(c);
    }
    return out;
}

std::vector<Cycle> highs_after(const PinLog& log, Cycle from) {
    std::vector<Cycle> out;
    const auto& e = log.edges();
    for (std::size_t i = 1; i < e.size(); ++i) {
        if (e[i - 1].cycle >= from && e[i - 1].level && !e[i].level) out.push_back(e[i].cycle - e[i - 1].cycle);
    }
    return out;
}

void expect_rate(const std::vector<Cycle>& rises, Cycle period) {
    ASSERT_GE(rises.size(), 2u);
    const auto intervals = PinLog::differences(rises);
    for (std::size_t i = 0; i < intervals.size(); ++i) {
        ASSERT_GE(intervals[i] + 1, period) << "interval " << i;
        ASSERT_LE(intervals[i], period + 1) << "interval " << i;
    }
    // The jitter does not add up: the first and last are period * (n - 1) +- 1 apart.
    const Cycle total = rises.back() - rises.front();
    EXPECT_GE(total + 1, period * (rises.size() - 1));
    EXPECT_LE(total, period * (rises.size() - 1) + 1);
}

void expect_pulses(const std::vector<Cycle>& highs, unsigned pulse_us) {
    const Bounds b = pulse_bounds(pulse_us);
    ASSERT_FALSE(highs.empty());
    const auto [lo, hi] = std::minmax_element(highs.begin(), highs.end());
    EXPECT_GE(*lo, b.min) << "pulse of " << pulse_us << " us";
    EXPECT_LE(*hi, b.max) << "pulse of " << pulse_us << " us";
}

TEST(GrblStepper, MoveOfXProducesItsExactStepCountRateAndPulseWidth) {
    Grbl g;
    const Cycle start = g.mcu().cycle();
    EXPECT_EQ(g.command("X1600"), "ok\r\n");
    const auto x = rises_after(g.step(0), start);
    EXPECT_EQ(x.size(), 1600u);
    EXPECT_TRUE(rises_after(g.step(1), start).empty());
    EXPECT_TRUE(rises_after(g.step(2), start).empty());
    // The first vector run found OCR1A = 0 (CTC at clk/1 since boot) and set it.
    EXPECT_EQ(g.mcu().read_ram_u16("ocr1a_first"), 0);
    expect_rate(x, kDefaultPeriod);
    expect_pulses(highs_after(g.step(0), start), 10);
    // Every pulse ended inside the step vector, after its sei(): nested.
    EXPECT_EQ(g.mcu().read_ram_u16("nested_ends"), 1600);
    // DIR X low before the first step (grbl drives DIR high for negative
    // moves: planner.c sets the direction bit when the axis' delta < 0);
    // drivers enabled (PB0 low) before the first step and disabled after the last.
    EXPECT_FALSE(g.mcu().pin("PD5").level());
    ASSERT_FALSE(x.empty());
    ASSERT_FALSE(g.enable().falls().empty());
    ASSERT_FALSE(g.enable().rises().empty());
    EXPECT_LT(g.enable().falls().back(), x.front());
    EXPECT_GT(g.enable().rises().back(), x.back());
    EXPECT_EQ(g.command("?"), "<1600,0,0>\r\nok\r\n");
}

// The idle-loop skipper between step interrupts (mcu/IdleLoopSkip): during
// a move the main loop is `while (running) {}`, a fixed point, and the step
// vector with its nested pulse-end vector stays under 1 000 cycles (the
// firmware's own bound: "well under the shortest step period (1000 cycles
// in the tests)"), so at least half of each 2 000-cycle step period is idle
// passes, which the skipper jumps over once it has watched one. (It skipped
// 40 % of a move when it began watching inside the interrupt's routine,
// which fails at the RETI and backs off; it waits for the loop's stack
// level now.) The steps are the same as without skipping (the test above).
TEST(GrblStepper, ControlCharactersAreDroppedAndEveryLineIsAnsweredOnce) {
    // grbl's protocol.c drops control characters and answers an empty line
    // "ok" (for syncing); a line ends at CR, LF or CR LF. The fuzzer found
    // the firmware's old reader ending a line at a leading NUL, unanswered.
    Grbl g;
    EXPECT_EQ(g.command(std::string("\0X16", 4)), "ok\r\n");
    EXPECT_EQ(g.command("?"), "<16,0,0>\r\nok\r\n");
    EXPECT_EQ(g.command(std::string("\0\0", 2)), "ok\r\n") << "nothing left: an empty line";
    EXPECT_EQ(g.command(""), "ok\r\n");
    // "?\r" + the "\n" command() adds: one line, one answer (a second "ok"
    // would answer a line the host never sent).
    const std::string answer = g.command("?\r");
    g.mcu().run_for(200000);  // 12.5 ms: room for a second answer (9 bytes take 0.8 ms at 115 200 baud)
    EXPECT_EQ(answer, "<16,0,0>\r\nok\r\n");
    EXPECT_EQ(g.command("?"), "<16,0,0>\r\nok\r\n") << "no answer left over from the CR LF line";
}

TEST(GrblStepper, IdlePassesBetweenStepInterruptsAreSkipped) {
    Grbl g;
    const Cycle start = g.mcu().cycle();
    const std::uint64_t skipped_before = g.mcu().idle_cycles_skipped();
    EXPECT_EQ(g.command("X1600"), "ok\r\n");
    const auto x = rises_after(g.step(0), start);
    ASSERT_EQ(x.size(), 1600u);
    const Cycle move_cycles = x.back() - x.front();  // 1 599 periods of 2 000 cycles
    const std::uint64_t skipped = g.mcu().idle_cycles_skipped() - skipped_before;
    EXPECT_GE(skipped, move_cycles / 2) << "skipped " << skipped << " of " << move_cycles;
}

TEST(GrblStepper, ThreeAxesStepInBresenhamProportionsInTheirDirections) {
    Grbl g;
    const Cycle start = g.mcu().cycle();
    EXPECT_EQ(g.command("X1600 Y-800 Z400"), "ok\r\n");
    const auto x = rises_after(g.step(0), start);
    EXPECT_EQ(x.size(), 1600u);
    EXPECT_EQ(rises_after(g.step(1), start).size(), 800u);
    EXPECT_EQ(rises_after(g.step(2), start).size(), 400u);
    EXPECT_FALSE(g.mcu().pin("PD5").level());  // X +: DIR low
    EXPECT_TRUE(g.mcu().pin("PD6").level());   // Y -: DIR high
    EXPECT_FALSE(g.mcu().pin("PD7").level());  // Z +: DIR low
    // X is the longest axis and sets the rate: 8000 steps/s, 2000 cycles.
    expect_rate(x, kDefaultPeriod);
    EXPECT_EQ(g.command("?"), "<1600,-800,400>\r\nok\r\n");
}

TEST(GrblStepper, SecondMoveStartsFromTheFlagSetWhileDisabled) {
    // After the first move the step vector is off but Timer1 keeps running
    // (CTC, OCR1A = 1999): OCF1A is set at every match. Enabling OCIE1A for
    // the next move runs the vector at once (§7.7), whose first run finds
    // OCR1A = 1999 now.
    Grbl g;
    EXPECT_EQ(g.command("X100"), "ok\r\n");
    const Cycle start = g.mcu().cycle();
    EXPECT_EQ(g.command("X-250"), "ok\r\n");
    EXPECT_EQ(rises_after(g.step(0), start).size(), 250u);
    EXPECT_EQ(g.mcu().read_ram_u16("ocr1a_first"), kDefaultPeriod - 1);
    EXPECT_TRUE(g.mcu().pin("PD5").level());  // X -: DIR high
    EXPECT_EQ(g.command("?"), "<-150,0,0>\r\nok\r\n");
}

TEST(GrblStepper, SettingsLiveInEepromAndSetTheRate) {
    Grbl g;
    // $100 = 160 steps/mm: G X10 is 1600 steps; the rate is 6000 * 160 / 60 =
    // 16000 steps/s, 1000 cycles per step. $0 = 5 us: a 10-clock pulse.
    EXPECT_EQ(g.command("$100=160"), "ok\r\n");
    EXPECT_EQ(g.command("$0=5"), "ok\r\n");
    const Cycle start = g.mcu().cycle();
    EXPECT_EQ(g.command("G X10"), "ok\r\n");
    const auto x = rises_after(g.step(0), start);
    EXPECT_EQ(x.size(), 1600u);
    expect_rate(x, 1000);
    expect_pulses(highs_after(g.step(0), start), 5);
    // The settings block at EEPROM 0: version, $0, $100 (little endian), ...
    avr_eeprom_desc_t desc{};
    desc.offset = 0;
    desc.size = 4;
    g.mcu().ioctl(AVR_IOCTL_EEPROM_GET, &desc);  // simavr returns -1 even when it worked
    ASSERT_NE(desc.ee, nullptr);
    EXPECT_EQ(desc.ee[0], 1);    // version
    EXPECT_EQ(desc.ee[1], 5);    // $0
    EXPECT_EQ(desc.ee[2], 160);  // $100 low byte
    EXPECT_EQ(desc.ee[3], 0);    // $100 high byte
    EXPECT_NE(g.command("$$").find("$100=160\r\n"), std::string::npos);
}

TEST(GrblStepper, LimitSwitchStopsTheMoveAtOnce) {
    Grbl g;
    const Cycle start = g.mcu().cycle();
    Pin& limit_x = g.mcu().pin("PB1");
    // Close the X limit switch (to ground) 1000 step periods into the move.
    std::size_t steps_at_trip = 0;
    g.mcu().scheduler().at(start + 1000 * kDefaultPeriod, [&](Cycle) {
        steps_at_trip = rises_after(g.step(0), start).size();
        limit_x.drive(false);
    });
    EXPECT_EQ(g.command("X1600"), "ALARM:1\r\n");
    const std::size_t steps = rises_after(g.step(0), start).size();
    // The pin change vector (§13 "External Interrupts", PCICR/PCMSK0: any change on PCINT1) disables the
    // step vector within a few dozen cycles, far less than one 2000-cycle step.
    EXPECT_GT(steps_at_trip, 900u);
    EXPECT_LE(steps, steps_at_trip + 1);
    g.mcu().run_for(100 * kDefaultPeriod);
    EXPECT_EQ(rises_after(g.step(0), start).size(), steps) << "steps after the alarm";
    EXPECT_EQ(g.command("X10"), "error:9\r\n");
    limit_x.release();  // the pull-up opens the switch input again
    EXPECT_EQ(g.command("$X"), "ok\r\n");
    const Cycle again = g.mcu().cycle();
    EXPECT_EQ(g.command("X10"), "ok\r\n");
    EXPECT_EQ(rises_after(g.step(0), again).size(), 10u);
}

}  // namespace
}  // namespace avrbench::test::timers
