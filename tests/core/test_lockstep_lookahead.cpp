// The lockstep's lookahead (core/Lockstep.hpp) changes only how fast a
// board runs: every board here is run twice, with lookahead and in strict
// lockstep (every MCU's horizon its present time), and must end in the same
// state - every MCU's cycle, PC and RAM, and every recorded event.
#include <gtest/gtest.h>
#include <sim_avr.h>

#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "core/Lockstep.hpp"
#include "printer3d/PrinterBench.hpp"
#include "support/Paths.hpp"
#include "trace/TimelineText.hpp"
#include "verify/Bench.hpp"

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
    bench.trace_board();
    bench.run_for(1.2);  // the setpoint write, two status reads, 586 PWM periods
    return end_state(bench);
}

TEST(LockstepLookahead, TwiHeaterLinkEndsAsInStrictLockstep) { expect_same(run_heater_link(false), run_heater_link(true)); }

EndState run_printer(bool lookahead) {
    auto bench = test::printer_bench();
    bench->board().lockstep().set_lookahead(lookahead);
    bench->trace_board();
    bench->host().add_lines("G28 X\nG1 X1 Y0.3 F600\nM3\nG2 X1 Y0.3 I0.5 J0 F300\nM5\nM104 S60\nM105\nM400\n");
    EXPECT_EQ(bench->run_until_idle(10.0), IdleResult::Idle);
    return end_state(*bench);
}

TEST(LockstepLookahead, FiveMcuPrinterEndsAsInStrictLockstep) { expect_same(run_printer(false), run_printer(true)); }

}  // namespace
}  // namespace avrbench
