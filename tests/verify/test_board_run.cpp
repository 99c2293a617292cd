// The library's board run as a C++ front end uses it (run/BoardRun.hpp):
// the firmware by MCU name, a streamed VCD, the summary and the verdict.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/Paths.hpp"
#include "support/RunCommand.hpp"
#include "run/BoardRun.hpp"
#include "trace/VcdReader.hpp"

namespace avrbench {
namespace {

TEST(BoardRun, RunsABoardFromTheCxxApiAndStreamsItsVcd) {
    const auto dir = test::scratch_dir("board-run");
    BoardRunOptions o;
    o.board = test::source_path("bench/boards/arduino-uno.yaml");
    o.firmware = {{"uno", test::firmware("blink_timer1")}};  // no `elf`: the map names the first MCU's too
    o.duration_ps = 20 * kPsPerMs;
    o.vcd = (dir / "blink.vcd").string();
    int progress_calls = 0;
    o.on_progress = [&](double, double) { ++progress_calls; };
    BoardRun run(std::move(o));
    run.run();
    EXPECT_EQ(run.verdict(false).outcome, RunVerdict::Outcome::Ok);
    EXPECT_GT(progress_calls, 0);
    // blink_timer1 toggles its LED (PB5, the board's `led` label) every 16000
    // cycles: 20 changes in 20 ms, at 20 different times in the VCD.
    const Timeline& t = run.bench().timeline();
    EXPECT_GE(t.recorded_count(), 20u);
    // Streamed: what was written left the timeline (memory stays bounded).
    EXPECT_LT(t.events().size(), t.recorded_count());
    std::ifstream vcd(dir / "blink.vcd");
    std::stringstream text;
    text << vcd.rdbuf();
    EXPECT_NE(text.str().find("$enddefinitions"), std::string::npos);
    std::size_t stamps = 0;
    for (std::size_t at = text.str().find("\n#"); at != std::string::npos; at = text.str().find("\n#", at + 1)) ++stamps;
    EXPECT_GE(stamps, 20u);
    // The LED's changes, read back: a toggle every 16000 cycles from Timer1's
    // first match, which comes 16000 cycles after main starts it - at most
    // 1000 cycles of start-up and setup in: the first toggle at 16000..17000
    // cycles, so 20 ms (320000 cycles) hold 19 or 20 toggles, besides the
    // initial value $dumpvars writes.
    const VcdDump dump = read_vcd((dir / "blink.vcd").string());
    const VcdVariable* led = dump.find("uno.PB5");
    ASSERT_NE(led, nullptr);
    EXPECT_GE(led->changes.size(), 1u + 19u);
    EXPECT_LE(led->changes.size(), 1u + 20u);
    EXPECT_TRUE(std::filesystem::exists(dir / "blink.gtkw"));
    const auto summary = run.summary();
    ASSERT_FALSE(summary.empty());
    EXPECT_NE(summary.front().find("avrbench run: board arduino-uno"), std::string::npos) << summary.front();
    bool firmware_line = false;
    for (const auto& line : summary) firmware_line = firmware_line || line.find("blink_timer1.elf") != std::string::npos;
    EXPECT_TRUE(firmware_line);
}

}  // namespace
}  // namespace avrbench
