// The in-process fuzz targets' snapshot (bench/fuzz/SnapshotHeap.hpp,
// FirmwareTarget.hpp), in a binary of its own: it replaces malloc, which the
// main suite's binary must not (and it is not built with sanitizers, whose
// malloc it would displace). A target boots once per process, so every test
// boots its board in a child and reads back what the child saw.
//
// What would make these fail: a piece of state the run changes outside the
// snapshot heap (a global, a cache, a buffer the region does not hold), a
// page written without the fault handler noting it, the allocator's own
// bookkeeping not rewound. Expected values come from the fork path, which
// gives each input a fresh copy of the booted process (the kernel's
// copy-on-write), and from the booted board read before any input ran.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "FirmwareTarget.hpp"
#include "SnapshotHeap.hpp"
#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "mcu/PredecodedCore.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

namespace fuzz = avrbench::fuzz;

// A guard against a hang, not a budget: each child runs a bounded number of
// inputs of bounded simulated time.
constexpr unsigned kChildGuardSeconds = 600;
constexpr std::uint32_t kMapSize = 1u << 16;

struct ChildResult {
    int status = 0;
    std::string text;
};

// Runs `body` in a forked child; its text comes back through a pipe.
ChildResult in_child(const std::function<std::string()>& body) {
    int fds[2];
    if (::pipe(fds) != 0) return {-1, "pipe failed"};
    const pid_t child = ::fork();
    if (child == 0) {
        ::close(fds[0]);
        ::alarm(kChildGuardSeconds);
        const std::string text = body();
        for (std::size_t at = 0; at < text.size();) {
            const ssize_t n = ::write(fds[1], text.data() + at, text.size() - at);
            if (n <= 0) ::_exit(3);
            at += static_cast<std::size_t>(n);
        }
        ::_exit(0);
    }
    ::close(fds[1]);
    ChildResult result;
    char buffer[65536];
    for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) result.text.append(buffer, static_cast<std::size_t>(n));
    ::close(fds[0]);
    ::waitpid(child, &result.status, 0);
    return result;
}

fuzz::TargetConfig config(const std::string& elf, const std::string& board, const std::string& family) {
    fuzz::TargetConfig c;
    c.elf = test::firmware(elf);
    c.board = board;
    c.family = family;
    return c;
}

std::string outcome_line(const fuzz::InputOutcome& outcome, const std::vector<std::uint8_t>& edges) {
    std::uint64_t hash = 0xcbf29ce484222325ull;  // FNV-1a of the edge map
    for (std::uint8_t e : edges) hash = (hash ^ e) * 0x100000001b3ull;
    std::ostringstream line;
    line << "steps " << outcome.steps << " edges " << std::hex << hash << std::dec << " finding "
         << (outcome.finding ? outcome.detail : "-");
    return line.str();
}

// Each input run twice from the booted board: in a forked child (the fork
// path), then in this process from the snapshot; one line per input and
// path, "fork: ..." and "restore: ...".
std::string both_paths(const fuzz::TargetConfig& c, const std::vector<std::string>& inputs) {
    fuzz::boot_target(c, "test_snapshot_heap");
    if (!fuzz::target_restores()) return "the target does not restore";
    std::string out;
    for (const std::string& input : inputs) {
        const ChildResult forked = in_child([&] {
            std::vector<std::uint8_t> edges(kMapSize);
            fuzz::InputOutcome outcome;
            fuzz::run_input(reinterpret_cast<const std::uint8_t*>(input.data()), input.size(), edges.data(),
                            kMapSize - 1, outcome);
            return outcome_line(outcome, edges);
        });
        out += "fork: " + forked.text + "\n";
    }
    for (const std::string& input : inputs) {
        std::vector<std::uint8_t> edges(kMapSize);
        fuzz::InputOutcome outcome;
        fuzz::run_input_and_restore(reinterpret_cast<const std::uint8_t*>(input.data()), input.size(), edges.data(),
                                    kMapSize - 1, outcome);
        out += "restore: " + outcome_line(outcome, edges) + "\n";
    }
    return out;
}

std::vector<std::string> lines_starting(const std::string& text, const std::string& prefix) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        if (line.rfind(prefix, 0) == 0) out.push_back(line.substr(prefix.size()));
    }
    return out;
}

void expect_paths_agree(const std::string& text, std::size_t inputs) {
    const auto forked = lines_starting(text, "fork: ");
    const auto restored = lines_starting(text, "restore: ");
    ASSERT_EQ(forked.size(), inputs) << text;
    ASSERT_EQ(restored.size(), inputs) << text;
    for (std::size_t i = 0; i < inputs; ++i) EXPECT_EQ(restored[i], forked[i]) << "input " << i << "\n" << text;
}

// Reached for the first time inside a Collecting scope (below).
const std::string& made_on_first_use() {
    static const std::string text(4096, 'x');
    return text;
}

}  // namespace

TEST(SnapshotHeap, IsAvailableInThisBuild) {
    // This binary is only built without sanitizers (tests/CMakeLists.txt),
    // where the snapshot heap owns malloc.
    EXPECT_TRUE(fuzz::snapshot_heap::available());
}

TEST(SnapshotHeap, RestoredBoardIsTheBootedBoardInEverythingARunObserves) {
    const ChildResult r = in_child([] {
        fuzz::boot_target(config("printer3d_interp", test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-alone.yaml"),
                                 "marlin"),
                          "test_snapshot_heap");
        const std::string booted = fuzz::observable_state();
        std::vector<std::uint8_t> edges(kMapSize);
        fuzz::InputOutcome outcome;
        // The first input runs outside the snapshot heap (SnapshotHeap.hpp).
        const std::string first = "M105\n";
        fuzz::run_input_and_restore(reinterpret_cast<const std::uint8_t*>(first.data()), first.size(), edges.data(),
                                    kMapSize - 1, outcome);
        const std::string after_first = fuzz::observable_state();
        // A move: the carriage, the step counters, the host's lines, RAM.
        const std::string move = "G1 X5 Y3 F3000\nM114\n";
        std::string after_move;
        {
            const fuzz::snapshot_heap::Collecting collecting;
            fuzz::run_input(reinterpret_cast<const std::uint8_t*>(move.data()), move.size(), edges.data(), kMapSize - 1,
                            outcome);
        }
        after_move = fuzz::observable_state();
        fuzz::snapshot_heap::restore();
        const std::string restored = fuzz::observable_state();
        const std::size_t pages = fuzz::snapshot_heap::pages_restored();
        return booted + "====\n" + after_first + "====\n" + after_move + "====\n" + restored + "====\npages " +
               std::to_string(pages) + "\n";
    });
    ASSERT_EQ(r.status, 0) << r.text;
    std::vector<std::string> parts;
    for (std::size_t start = 0;;) {
        const std::size_t end = r.text.find("====\n", start);
        if (end == std::string::npos) {
            parts.push_back(r.text.substr(start));
            break;
        }
        parts.push_back(r.text.substr(start, end - start));
        start = end + 5;
    }
    ASSERT_EQ(parts.size(), 5u) << r.text;
    const std::string& booted = parts[0];
    // The fixture's one MCU is named "interp".
    EXPECT_NE(booted.find("interp.data 8704:"), std::string::npos) << booted;     // ATmega2560: RAMEND 0x21FF
    EXPECT_NE(booted.find("interp.flash 262144:"), std::string::npos) << booted;  // 256 KiB
    EXPECT_NE(booted.find("interp.eeprom 4096:"), std::string::npos) << booted;   // 4 KiB
    EXPECT_EQ(parts[1], booted) << "after the first input (restored)";
    EXPECT_NE(parts[2], booted) << "the move must change what a run observes, or this test proves nothing";
    EXPECT_EQ(parts[3], booted) << "after the move, restored";
    EXPECT_NE(parts[4], "pages 0\n");
}

TEST(SnapshotHeap, RestoredRunsFindWhatForkedRunsFindOnTheThesisParser) {
    // Seed 001's thesis parser (Code 4.11 as printed): a line longer than its
    // 50-byte buffer overruns the stack (strcpy); the board's 0.5 s line
    // timeout catches a line it never answers.
    const std::vector<std::string> inputs = {
        "G1 X10 F600\n", "M105\n", "G1 X" + std::string(70, '1') + "\n", "G28\nG1 X1 Y1 F1200\nM114\n", "M105\n",
        "G1 X" + std::string(70, '2') + "\n", "G91\nG1 X2\nG90\n"};
    const ChildResult r = in_child([&] {
        return both_paths(config("printer3d_interp_thesis_parser",
                                 test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-thesis.yaml"), "marlin"),
                          inputs);
    });
    ASSERT_EQ(r.status, 0) << r.text;
    expect_paths_agree(r.text, inputs.size());
    const auto restored = lines_starting(r.text, "restore: ");
    ASSERT_EQ(restored.size(), inputs.size());
    EXPECT_NE(restored[0].find("finding timeout: line 1 'G1 X10 F600' got no answer within 0.5 s"), std::string::npos)
        << "the unanswered line\n" << r.text;
    EXPECT_NE(restored[2].find("strcpy"), std::string::npos) << "the overrun, in strcpy\n" << r.text;
    EXPECT_NE(restored[1].find("finding -"), std::string::npos) << "M105 is not\n" << r.text;
}

TEST(SnapshotHeap, RestoredRunsFindWhatForkedRunsFindOnGrbl) {
    const std::vector<std::string> inputs = {"X160\n", "G X1\n", "$$\n", "?\n", "G1 X5 Y2 F500\n", "G0 X-3\n$X\n", "X160\n"};
    const ChildResult r = in_child([&] {
        return both_paths(config("grbl_stepper", test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml"), "generic"),
                          inputs);
    });
    ASSERT_EQ(r.status, 0) << r.text;
    expect_paths_agree(r.text, inputs.size());
    const auto restored = lines_starting(r.text, "restore: ");
    ASSERT_EQ(restored.size(), inputs.size());
    // The same input first and last: the board it met was the same.
    EXPECT_EQ(restored.front(), restored.back()) << r.text;
}

TEST(SnapshotHeap, AFunctionLocalStaticFirstReachedByAnInputOutlivesTheRestore) {
    // A static made during an input, on the region, would point into memory
    // the next restore takes back; the guard hooks put it on the process heap.
    const ChildResult r = in_child([] {
        fuzz::boot_target(config("printer3d_interp", test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-alone.yaml"),
                                 "marlin"),
                          "test_snapshot_heap");
        // Only booleans cross the restore: anything allocated in the scope is taken back by it.
        bool ordinary_in_region = false, static_in_region = false;
        {
            const fuzz::snapshot_heap::Collecting collecting;
            // The control: an ordinary allocation in the scope is the region's.
            auto* ordinary = new std::string(4096, 'y');
            ordinary_in_region = fuzz::snapshot_heap::holds(ordinary->data());
            delete ordinary;
            static_in_region = fuzz::snapshot_heap::holds(made_on_first_use().data());
        }
        fuzz::snapshot_heap::restore();
        std::string out = std::string("ordinary ") + (ordinary_in_region ? "region" : "process") + "\n";
        out += std::string("static ") + (static_in_region ? "region" : "process") + "\n";
        out += "after restore " + std::to_string(made_on_first_use().size()) + " " + made_on_first_use().substr(0, 3) + "\n";
        return out;
    });
    ASSERT_EQ(r.status, 0) << r.text;
    EXPECT_EQ(r.text, "ordinary region\nstatic process\nafter restore 4096 xxx\n");
}

// The predecoded core's slots live on the process heap (a restore keeps
// what earlier inputs decoded), the flash in the region. An input whose SPM
// rewrote decoded code leaves slots for that code; after the restore the
// flash holds the old code again, and the batch must run the old code.
// Opcodes and SPM sequence as in tests/core/test_predecoded_core.cpp
// (BatchRunsWhatAnSpmWroteOverDecodedCode): LDI r16, K = 0xE000 | (K & 0xF0)
// << 4 | (K & 0x0F); WDR = 0x95A8; OUT SPMCSR (I/O 0x37), r20 = 0xBF47;
// SPM = 0x95E8; SPMCSR SPMEN = 1, PGERS = 2, PGWRT = 4.
TEST(SnapshotHeap, ARestoreUndoesWhatAnInputsSpmDidToTheDecodedCode) {
    const ChildResult r = in_child([] {
        Mcu* mcu = nullptr;
        PredecodedCore* core = nullptr;
        {
            const fuzz::snapshot_heap::Collecting collecting;
            mcu = new Mcu(ElfImage::load(test::firmware("busy_poll")), McuOptions{});
            core = new PredecodedCore(mcu->avr(), mcu->avr()->flashend - 1);
        }
        avr_t* avr = mcu->avr();
        const auto put = [&](avr_flashaddr_t at, std::uint16_t word) {
            avr->flash[at] = static_cast<std::uint8_t>(word);
            avr->flash[at + 1] = static_cast<std::uint8_t>(word >> 8);
        };
        const avr_flashaddr_t page = 0x1000;
        const avr_flashaddr_t boot = (avr->flashend + 1) - 256;  // in every BOOTSZ's boot section
        put(page, 0xE102);                                       // LDI r16, 0x12
        put(page + 2, 0x95A8);
        put(boot, 0xBF47);
        put(boot + 2, 0x95E8);
        const auto run_page = [&] {
            avr->pc = page;
            const PredecodedCore::BatchLimits limits{avr->cycle + 1'000'000, 100, static_cast<std::uint32_t>(avr->flashend - 1), ~0u, 0};
            core->run_batch<false>(avr, limits, nullptr);
            return static_cast<unsigned>(avr->data[16]);
        };
        const auto spm = [&](std::uint8_t spmcsr, avr_flashaddr_t z, std::uint16_t r1_r0) {
            avr->data[20] = spmcsr;
            avr->data[R_ZL] = static_cast<std::uint8_t>(z);
            avr->data[R_ZH] = static_cast<std::uint8_t>(z >> 8);
            avr->data[0] = static_cast<std::uint8_t>(r1_r0);
            avr->data[1] = static_cast<std::uint8_t>(r1_r0 >> 8);
            avr->pc = boot;
            avr->pc = core->run_one(avr);
            avr->pc = core->run_one(avr);
        };
        std::ostringstream out;
        out << "booted " << std::hex << run_page();
        fuzz::snapshot_heap::take();
        spm(0x01, page, 0xE304);  // LDI r16, 0x34
        spm(0x01, page + 2, 0x95A8);
        spm(0x03, page, 0);
        spm(0x05, page, 0);
        out << " input " << run_page();
        fuzz::snapshot_heap::restore();
        out << " restored " << run_page() << "\n";
        return out.str();
    });
    ASSERT_EQ(r.status, 0) << r.text;
    EXPECT_EQ(r.text, "booted 12 input 34 restored 12\n");
}

TEST(SnapshotHeap, AFaultOutsideTheRegionStillKillsTheProcess) {
    // The write-protection handler takes the faults in its region only: a
    // bench bug elsewhere must still end the process (a crash the engine
    // sees), neither swallowed nor retried forever (the guard would end that).
    const ChildResult r = in_child([] {
        fuzz::boot_target(config("printer3d_interp", test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-alone.yaml"),
                                 "marlin"),
                          "test_snapshot_heap");
        void* page = ::mmap(nullptr, 4096, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (page == MAP_FAILED) return std::string("mmap failed");
        *static_cast<volatile int*>(page) = 1;
        return std::string("survived the write");
    });
    EXPECT_TRUE(WIFSIGNALED(r.status) && WTERMSIG(r.status) == SIGSEGV) << "status 0x" << std::hex << r.status << ": " << r.text;
}

// The target's per-input bound beyond the flat one (FirmwareTarget.hpp,
// AVRBENCH_FUZZ_STEADY), on grbl_stepper and the UNO + CNC shield board:
// 250 steps/mm, 200 mm of travel, carriages start at 100 mm
// (bench/boards/arduino-uno-cnc-shield-v3.yaml); grbl_stepper steps at
// 8 000 steps/s by default ($110 = 6000 mm/min at $100 = 80 steps/mm:
// firmware/boards/grbl_stepper/main.c).
namespace {

std::string run_one(const fuzz::TargetConfig& c, const std::string& input) {
    fuzz::boot_target(c, "test_snapshot_heap");
    std::vector<std::uint8_t> edges(kMapSize);
    fuzz::InputOutcome outcome;
    fuzz::run_input(reinterpret_cast<const std::uint8_t*>(input.data()), input.size(), edges.data(), kMapSize - 1,
                    outcome);
    return "steady " + std::to_string(outcome.ended_steady ? 1 : 0) + " " + outcome_line(outcome, edges);
}

std::uint64_t steps_of(const std::string& line) {
    const auto at = line.find("steps ");
    return at == std::string::npos ? 0 : std::stoull(line.substr(at + 6));
}

fuzz::TargetConfig cnc_shield(double bound_s, std::uint64_t steady_instructions) {
    fuzz::TargetConfig c = config("grbl_stepper", test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml"), "generic");
    c.bound_s = bound_s;
    c.steady_instructions = steady_instructions;
    return c;
}

}  // namespace

TEST(FuzzTarget, AMoveThatOnlyRepeatsItselfEndsBeforeItsBound) {
    // X16000: 2 s of step interrupts, 20 mm from 100 mm, inside the 3 s bound
    // and far from either end of travel even going on for the whole bound
    // (3 s x 32 mm/s = 96 mm < 100 mm). Its step vector stops adding
    // coverage after its 128th run (libFuzzer's last hit-count bucket), so
    // it ends the default 100 000 instructions later: under 1 M of the full
    // move's 16 000 vector runs of hundreds of instructions each.
    const ChildResult cut = in_child([] {
        return run_one(cnc_shield(3.0, fuzz::TargetConfig{}.steady_instructions), "X16000\n");
    });
    ASSERT_EQ(cut.status, 0) << cut.text;
    EXPECT_EQ(cut.text.rfind("steady 1 ", 0), 0u) << cut.text;
    EXPECT_NE(cut.text.find("finding -"), std::string::npos) << cut.text;
    EXPECT_LT(steps_of(cut.text), 1000000u) << cut.text;
    // The same without the steady bound: the whole move, at least one vector run per step.
    const ChildResult whole = in_child([] { return run_one(cnc_shield(3.0, 0), "X16000\n"); });
    ASSERT_EQ(whole.status, 0) << whole.text;
    EXPECT_EQ(whole.text.rfind("steady 0 ", 0), 0u) << whole.text;
    EXPECT_GT(steps_of(whole.text), 16000u * 100u) << whole.text;
}

TEST(FuzzTarget, AMoveThatReachesAnEndOfTravelWithinTheBoundRunsToItsCrash) {
    // X30000 from 100 mm: 100 mm (25 000 steps) to the upper end, reached
    // after 25 000 / 8 000 = 3.125 s - within a 5 s bound, so the carriage's
    // pace says a finding is ahead and the input is not cut.
    const ChildResult r = in_child([] { return run_one(cnc_shield(5.0, fuzz::TargetConfig{}.steady_instructions), "X30000\n"); });
    ASSERT_EQ(r.status, 0) << r.text;
    EXPECT_EQ(r.text.rfind("steady 0 ", 0), 0u) << r.text;
    EXPECT_NE(r.text.find("axis-out-of-travel"), std::string::npos) << r.text;
    EXPECT_NE(r.text.find("past the upper end of travel"), std::string::npos) << r.text;
}

TEST(FuzzTarget, AGenericFirmwareGetsItsInputAfterItsBanner) {
    // grbl_stepper writes its default settings to EEPROM at its first boot
    // (15 bytes, each a 3.4 ms EEPE busy wait: about 50 ms, 800 000 cycles)
    // before its banner. Booted to the banner, an input of '?' is only its
    // own answer: 11 characters sent at 115 200 baud, polled.
    const ChildResult r = in_child([] { return run_one(cnc_shield(3.0, fuzz::TargetConfig{}.steady_instructions), "?\n"); });
    ASSERT_EQ(r.status, 0) << r.text;
    EXPECT_LT(steps_of(r.text), 100000u) << r.text;
}

}  // namespace avrbench
