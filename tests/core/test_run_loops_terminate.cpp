// Every loop that runs the simulation either advances simulated time or
// stops. Simulated time is compared as integers (core/Time.hpp); before that,
// a board that landed exactly on its end compared one ulp short in double
// seconds (2e11 ps * 1e-12 = 0.19999999999999998 < 0.2) and the run loop
// asked again and again for a time already reached.
//
// The sweep runs >= 200 durations over a busy, a sleeping and a two-clock
// board, each board's sweep in a child process under a wall-clock guard, so
// a regression fails here instead of hanging CI.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "boards/Board.hpp"
#include "mcu/Lockstep.hpp"
#include "core/Units.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"
#include "support/WallClockGuard.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

namespace fs = std::filesystem;

// Durations users type (the ones that hung first), odd nanoseconds, thirds
// and sevenths of a millisecond (no clock period divides them), and a ramp
// of whole milliseconds (every one of them once compared short as a double).
std::vector<std::string> sweep_durations() {
    std::vector<std::string> out = {"10ms", "50ms", "100ms", "200ms", "250ms", "700ms", "1s"};
    for (int ms = 1; ms <= 120; ++ms) out.push_back(std::to_string(ms) + "ms");
    for (int k = 1; k <= 40; ++k) out.push_back(std::to_string(k * 1'000'003 + 7) + "ns");
    for (int k = 1; k <= 20; ++k) out.push_back(std::to_string(k / 3.0) + "ms");
    for (int k = 1; k <= 20; ++k) out.push_back(std::to_string(k / 7.0) + "ms");
    out.push_back("1ns");
    out.push_back("62ns");   // less than one 16 MHz cycle
    out.push_back("63ns");
    out.push_back("0s");
    return out;
}

// The CLI's loop: chunks of 1/100 of the run until the board reaches the end.
std::string run_chunked(Board& board, Picoseconds end_ps) {
    const Picoseconds chunk = std::max<Picoseconds>(end_ps / 100, 1'000'000);
    std::size_t passes = 0;
    while (board.now_ps() < end_ps) {
        const Picoseconds before = board.now_ps();
        if (board.run_until_ps(std::min(end_ps, add_ps(before, chunk))) == StopReason::Halted) return "halted";
        if (board.now_ps() <= before) return "no progress at " + std::to_string(before) + " ps";
        if (++passes > 200) return "more than 200 passes for 100 chunks";
    }
    return "";
}

std::string sweep(const std::string& board_file, const std::map<std::string, std::string>& firmware) {
    std::string failures;
    std::size_t runs = 0;
    for (const auto& text : sweep_durations()) {
        const Picoseconds d = parse_duration_ps(text, "duration");
        {
            Bench bench(board_file, firmware);
            const std::string why = run_chunked(bench.board(), d);
            if (!why.empty()) failures += text + " (chunked): " + why + "\n";
            // Every MCU stands at the first cycle at or after d (exact rationals).
            for (Mcu* m : bench.board().mcus()) {
                if (m->cycle() < cycle_at_ps(*m, d)) failures += text + ": " + m->name() + " stopped short\n";
            }
            if (bench.now_ps() < d) failures += text + ": board time short of the end\n";
        }
        {
            // A host whose line is never answered: run_until_idle must end at
            // the limit (the firmware here never reads its UART).
            Bench bench(board_file, firmware);
            bench.host().add_line("G1 X1");
            const IdleResult r = bench.run_until_idle_ps(d, 50'000'000'000);
            if (r != IdleResult::TimeLimit) failures += text + " (idle): " + to_string(r) + "\n";
            if (bench.now_ps() < d) failures += text + " (idle): stopped before the limit\n";
        }
        runs += 2;
    }
    if (runs < 200) failures += "only " + std::to_string(runs) + " runs\n";
    return failures;
}

TEST(RunLoopsTerminate, BusyFirmwareOnOneMcu) {
    const std::string why = test::run_guarded(240, [] {
        return sweep(test::source_path("bench/boards/arduino-uno.yaml"), {{"uno", test::firmware("busy_poll")}});
    });
    EXPECT_EQ(why, "");
}

TEST(RunLoopsTerminate, SleepingFirmwareOnOneMcu) {
    const std::string why = test::run_guarded(240, [] {
        return sweep(test::source_path("bench/boards/arduino-uno.yaml"), {{"uno", test::firmware("sleep_idle")}});
    });
    EXPECT_EQ(why, "");
}

TEST(RunLoopsTerminate, TwoMcusWithUnrelatedClocks) {
    const std::string why = test::run_guarded(240, [] {
        return sweep(test::source_path("tests/fixtures/boards/two-clocks.yaml"),
                     {{"fast", test::firmware("busy_poll")}, {"uart_crystal", test::firmware("sleep_idle")}});
    });
    EXPECT_EQ(why, "");
}

// The exact commands that hung, through the CLI, each under a wall-clock limit.
TEST(RunLoopsTerminate, CliRunsThatUsedToHang) {
    const auto dir = test::scratch_dir("cli-hang");
    const std::string cli = ::avrbench::test::cli();
    const std::string board = test::source_path("bench/boards/arduino-uno.yaml");
    // Each ends exactly at its limit: "simulated  0.050000 s" ... (the summary's 6 decimals).
    for (const auto& [t, shown] : {std::pair{"50ms", "0.050000"}, std::pair{"100ms", "0.100000"}, std::pair{"200ms", "0.200000"},
                                   std::pair{"700ms", "0.700000"}}) {
        const auto r = test::run_command(cli + " run -q --board " + board + " " + test::firmware("busy_poll") + " --for " + t, dir, 60);
        EXPECT_EQ(r.exit_code, 0) << t << ": " << r.err;
        EXPECT_NE(r.out.find(std::string("simulated  ") + shown + " s"), std::string::npos) << t << ": " << r.out;
    }
    // A scenario whose awaited text never comes ends at its time limit.
    const fs::path scenario = dir / "never.yaml";
    std::ofstream(scenario) << "board: " << board << "\n"
                            << "firmware: {uno: busy_poll}\n"
                            << "time_limit: 100ms\n"
                            << "steps:\n  - wait_for_text: never\n";
    const auto r = test::run_command(cli + " check " + scenario.string() + " --firmware-dir " + ::avrbench::test::firmware_dir(), dir, 60);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.out.find("the firmware sent no line containing 'never' by 0.100000 s"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace avrbench
