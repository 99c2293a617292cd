// The lockstep's lookahead (mcu/Lockstep.hpp) changes only how fast a
// board runs: every board here is run twice, with lookahead and in strict
// lockstep (every MCU's horizon its present time), and must end in the same
// state - every MCU's cycle, PC and RAM, and every recorded event. Both runs
// also check, every turn, that the turn entries the lockstep keeps for MCUs
// that did not run equal ones worked out anew.
#include <gtest/gtest.h>
#include <sim_avr.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "mcu/Lockstep.hpp"
#include "printer3d/PrinterBench.hpp"
#include "support/Paths.hpp"
#include "trace/TimelineText.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

struct EndState {
    std::string timeline;
    std::vector<Cycle> cycles;
    std::vector<std::uint32_t> pcs;
    std::vector<std::vector<std::uint8_t>> ram;
    std::uint64_t catch_ups = 0;
};

EndState end_state(Bench& bench) {
    EndState s;
    s.timeline = format_timeline_text(bench.timeline(), TimelineHeader{});
    for (Mcu* m : bench.board().mcus()) {
        s.cycles.push_back(m->cycle());
        s.pcs.push_back(m->pc_bytes());
        // All of the data space: registers, I/O, SRAM.
        s.ram.push_back(m->data_memory());
    }
    s.catch_ups = bench.board().lockstep().catch_ups();
    return s;
}

void expect_same(const EndState& strict, const EndState& fast) {
    EXPECT_EQ(strict.cycles, fast.cycles);
    EXPECT_EQ(strict.pcs, fast.pcs);
    EXPECT_TRUE(strict.ram == fast.ram) << "data space differs";
    EXPECT_EQ(strict.timeline.size(), fast.timeline.size());
    EXPECT_TRUE(strict.timeline == fast.timeline) << "timelines differ";
    // Strict lockstep catches a sleeping core up by the few cycles of the
    // last instruction only; the lookahead passes sleeping cores by far more.
    EXPECT_GT(fast.catch_ups, strict.catch_ups);
}

EndState run_heater_link(bool lookahead) {
    Bench bench(test::source_path("bench/boards/printer3d-heater-seed001.yaml"),
                {{"host", test::firmware("printer3d_heater_probe_60")}, {"heater", test::firmware("printer3d_heater")}});
    bench.board().lockstep().set_lookahead(lookahead);
    bench.board().lockstep().set_check_turns(true);
    bench.trace_board();
    bench.run_for(1.2);  // the setpoint write, two status reads, 586 PWM periods
    return end_state(bench);
}

TEST(LockstepLookahead, TwiHeaterLinkEndsAsInStrictLockstep) { expect_same(run_heater_link(false), run_heater_link(true)); }

EndState run_printer(bool lookahead) {
    auto bench = test::printer_bench();
    bench->board().lockstep().set_lookahead(lookahead);
    bench->board().lockstep().set_check_turns(true);
    bench->trace_board();
    // M104 S0 last: the heater off again, so the run is done without waiting
    // for 60 degC (Bench::still_going) - the TWI traffic is what counts here.
    bench->host().add_lines("G28 X\nG1 X1 Y0.3 F600\nM3\nG2 X1 Y0.3 I0.5 J0 F300\nM5\nM104 S60\nM105\nM400\nM104 S0\n");
    EXPECT_EQ(bench->run_until_idle(10.0), IdleResult::Idle);
    return end_state(*bench);
}

TEST(LockstepLookahead, FiveMcuPrinterEndsAsInStrictLockstep) { expect_same(run_printer(false), run_printer(true)); }

// A chain across four MCUs: `source` (sleep_idle) toggles PB5 every 10 ms;
// `woken` relays it from its PCINT1 interrupt (pcint_relay_wake), `polled`
// from a Timer0 overflow every 1.024 ms (pcint_relay_poll: no pin change
// wakes it); `busy` (busy_poll) is joined to nothing and never sleeps. The
// lookahead lets `polled` run past `woken` and everything run past `busy`;
// `woken`'s bound is `source`'s next timer, and `polled`'s is `woken`'s next
// action, which is `source`'s (a change of PB1 wakes `woken`).
constexpr const char* kRelayChain = R"(
board: relay-chain
mcus:
  source: {type: atmega328p, clock: 16MHz}
  woken: {type: atmega328p, clock: 16MHz}
  polled: {type: atmega328p, clock: 16MHz}
  busy: {type: atmega328p, clock: 16MHz}
nets:
  first: [source.PB5, woken.PB1]
  second: [woken.PC0, polled.PB1]
labels:
  relayed: polled.PC0
)";

std::unique_ptr<Bench> relay_chain(bool lookahead, const char* woken_firmware = "pcint_relay_wake") {
    auto bench = std::make_unique<Bench>(parse_board_text(kRelayChain, "relay-chain.yaml"),
                                         std::map<std::string, std::string>{
                                             {"source", test::firmware("sleep_idle")},
                                             {"woken", test::firmware(woken_firmware)},
                                             {"polled", test::firmware("pcint_relay_poll")},
                                             {"busy", test::firmware("busy_poll")}});
    bench->board().lockstep().set_lookahead(lookahead);
    bench->board().lockstep().set_check_turns(true);
    bench->trace_board();
    bench->run_for(0.105);  // ten toggles of the source, one every 10 ms
    return bench;
}

TEST(LockstepLookahead, RelayChainEndsAsInStrictLockstep) {
    auto strict = relay_chain(false);
    auto fast = relay_chain(true);
    expect_same(end_state(*strict), end_state(*fast));
}

// `woken` opens and closes its pin-change gate every 1.024 ms
// (pcint_relay_gated): whether `source` can wake it changes while it runs,
// so what the lockstep remembers of it must be worked out again each time
// (the turn check fails when it is not).
TEST(LockstepLookahead, RelayChainWithAGatedWakeUpEndsAsInStrictLockstep) {
    auto strict = relay_chain(false, "pcint_relay_gated");
    auto fast = relay_chain(true, "pcint_relay_gated");
    expect_same(end_state(*strict), end_state(*fast));
}

// What the chain does, timed by the datasheet, not by the other run.
TEST(LockstepLookahead, RelayChainFollowsTheSourceAtEachLinksLatency) {
    auto bench = relay_chain(true);
    Board& board = bench->board();
    std::vector<double> source_s, woken_s, polled_s;
    const Timeline& timeline = bench->timeline();
    const auto edges_of = [&](const std::string& scope, const std::string& name, std::vector<double>& out) {
        for (const auto& e : timeline.events()) {
            const auto& signal = timeline.signals()[e.signal];
            if (signal.scope == scope && signal.name == name && e.cycle != 0) {
                out.push_back(static_cast<double>(e.cycle) / signal.clock_hz);
            }
        }
    };
    edges_of("source", "PB5", source_s);
    edges_of("woken", "PC0", woken_s);
    edges_of("polled", "PC0", polled_s);
    ASSERT_EQ(source_s.size(), 10u) << "sleep_idle toggles PB5 every 10 ms";
    ASSERT_EQ(woken_s.size(), source_s.size());
    ASSERT_EQ(polled_s.size(), source_s.size());
    for (std::size_t i = 0; i < source_s.size(); ++i) {
        // Waking from IDLE (4 cycles, §10.1), the interrupt's entry (4) and
        // jump, the ISR's prologue and the copy: well under 64 cycles.
        EXPECT_GT(woken_s[i], source_s[i]);
        EXPECT_LT(woken_s[i] - source_s[i], 64 / 16e6) << "edge " << i;
        // The poll: the next Timer0 overflow, at most 16384 cycles later, plus the same.
        EXPECT_GT(polled_s[i], woken_s[i]);
        EXPECT_LT(polled_s[i] - woken_s[i], (16384 + 64) / 16e6) << "edge " << i;
    }
    EXPECT_EQ(board.mcu("polled").read_ram_u16("copies"), 102u);  // 0.105 s * 16 MHz / 16384, rounded down
}

// Which pins can wake a sleeping MCU, from its registers (Mcu::pin_change_may_interrupt).
TEST(LockstepLookahead, APinWakesOnlyWithItsInterruptOrPeripheral) {
    auto bench = relay_chain(true);
    Mcu& woken = bench->board().mcu("woken");
    Mcu& polled = bench->board().mcu("polled");
    EXPECT_TRUE(woken.pin_change_may_interrupt(woken.pin("PB1")));    // PCMSK0.PCINT1 with PCICR.PCIE0
    EXPECT_FALSE(polled.pin_change_may_interrupt(polled.pin("PB1")));  // PCINT off
    EXPECT_FALSE(woken.pin_change_may_interrupt(woken.pin("PC1")));   // a plain pin
    EXPECT_TRUE(woken.pin_change_may_interrupt(woken.pin("PB0")));    // ICP1 (328P §14.3.1)
    EXPECT_TRUE(woken.pin_change_may_interrupt(woken.pin("PD0")));    // RXD
    EXPECT_TRUE(woken.pin_change_may_interrupt(woken.pin("PC4")));    // SDA
}

}  // namespace
}  // namespace avrbench
