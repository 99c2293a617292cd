// `avrbench fuzz` smoke runs (issue 16's CI bound, issue 31's load-proof
// form): every campaign is bounded by a number of executions (--runs) with
// --seed 1, so it makes the same inputs on any machine however loaded; the
// wall clock (--for 600s, and the command's guard) only stops a run that
// hangs. On seed 001's interpolator alone, the thesis' parser (Code 4.11 as
// printed) has two planted bugs - a line it cannot finish is never answered,
// a line longer than its 50-byte buffer overruns the stack (strcpy) - and
// the fuzzer must find both; the improved build must give nothing. The
// thesis run's board has a 0.5 s line timeout (see its file: the listing
// sends no keep-alive). The seed corpus holds well-formed lines only; the
// overrun comes from the search. The same with AFL++ (--engine afl, its own
// fork server in the target, the G-code mutator as its custom mutator, -E).
// Seed 004's delta: the out-of-table angle with AFL++, nothing in the
// improved build. Measured with these seeds (the same on every run):
// libFuzzer (one job, in one process) had both bugs by its 17th execution
// (bound: 600); AFL++ the stack overrun at execution 55 and the unanswered
// line at 73 (bound: 1500), the delta's out-of-table pulse at 4098 (bound:
// 5000; 198 before inputs ran until the firmware was done, not 100 ms past
// their last answer, which changed AFL++'s course). The improved builds must
// give nothing in 1000.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

// A guard, not a budget: a campaign ends at its --runs long before this.
constexpr int kCampaignGuardSeconds = 600;

std::string fuzz(const std::string& elf, const std::string& board, const std::string& runs, const std::filesystem::path& dir,
                 int* exit_code, const std::string& engine = "libfuzzer") {
    const std::string command = std::string(::avrbench::test::cli()) + " fuzz --engine " + engine + " --elf " + test::firmware(elf) +
                                " --board " + test::source_path("tests/fixtures/fuzz/firmware/" + board) + " --runs " + runs +
                                " --for " + std::to_string(kCampaignGuardSeconds) + "s --seed 1 --out " + (dir / "out").string();
    const auto r = test::run_command(command, dir, kCampaignGuardSeconds + 60);
    *exit_code = r.exit_code;
    return r.out + r.err;
}

// "firmware edge features 2186 at the start, 7015 at the end" -> {2186, 7015};
// AFL++: "firmware edge tuples (AFL++'s edges) 1737 at the start, 2400 at the end".
std::pair<long, long> features(const std::string& out) {
    long first = -1, last = -1;
    if (const auto at = out.find("firmware edge features "); at != std::string::npos) {
        std::sscanf(out.c_str() + at, "firmware edge features %ld at the start, %ld at the end", &first, &last);
    } else if (const auto afl = out.find("(AFL++'s edges) "); afl != std::string::npos) {
        std::sscanf(out.c_str() + afl, "(AFL++'s edges) %ld at the start, %ld at the end", &first, &last);
    }
    return {first, last};
}

// A crash's root cause names its function: "interp: simavr-crash in strcpy".
bool reports_a_crash(const std::string& out) {
    return out.find("simavr-crash in ") != std::string::npos || out.find("pc-outside-program in ") != std::string::npos ||
           out.find("pc-outside-program from ") != std::string::npos || out.find("stack-overflow in ") != std::string::npos ||
           out.find("invalid-opcode in ") != std::string::npos;
}

TEST(Fuzz, FindsTheThesisParsersPlantedBugs) {
    const auto dir = test::scratch_dir("fuzz-thesis");
    int code = 0;
    const std::string out = fuzz("printer3d_interp_thesis_parser", "printer3d-interp-thesis.yaml", "600", dir, &code);
    EXPECT_EQ(code, 1) << out;
    // A root cause per kind and shape of line: "timeout on 'G1 F X' lines".
    EXPECT_NE(out.find(". timeout on '"), std::string::npos) << out;
    EXPECT_NE(out.find("got no answer within 0.5 s"), std::string::npos) << out;
    EXPECT_TRUE(reports_a_crash(out)) << out;
    const auto [first, last] = features(out);
    EXPECT_GT(first, 0) << out;
    EXPECT_GT(last, first) << "coverage must grow over the run\n" << out;
    EXPECT_NE(out.find("findings/finding-1.txt, " + (dir / "out/findings/finding-1.vcd").string()), std::string::npos) << out;
    EXPECT_TRUE(std::filesystem::exists(dir / "out/findings/finding-1.vcd"));
    // Each root cause says when the engine first found it: within the fuzzing's own time.
    double fuzzing_s = -1;
    unsigned long executions = 0;
    if (const auto at = out.find("  executions "); at != std::string::npos) {
        std::sscanf(out.c_str() + at, "  executions %lu in %lf s", &executions, &fuzzing_s);
    }
    ASSERT_GT(fuzzing_s, 0) << out;
    std::size_t told = 0;
    for (auto at = out.find("; first found "); at != std::string::npos; at = out.find("; first found ", at + 1)) {
        double first_s = -1;
        ASSERT_EQ(std::sscanf(out.c_str() + at, "; first found %lf s into the fuzzing)", &first_s), 1) << out;
        EXPECT_GE(first_s, 0.0) << out;
        EXPECT_LE(first_s, fuzzing_s + 1.0) << out;  // a file time's and a clock's resolution
        ++told;
    }
    EXPECT_GE(told, 2u) << out;  // the timeout and the crash
}

TEST(Fuzz, FindsNothingInTheImprovedInterpolator) {
    const auto dir = test::scratch_dir("fuzz-improved");
    int code = 0;
    const std::string out = fuzz("printer3d_interp", "printer3d-interp-alone.yaml", "1000", dir, &code);
    EXPECT_EQ(code, 0) << out;
    EXPECT_NE(out.find("findings   0 distinct"), std::string::npos) << out;
    EXPECT_NE(out.find(" per second)"), std::string::npos) << out;
}

TEST(Fuzz, AflFindsTheThesisParsersPlantedBugs) {
    const auto dir = test::scratch_dir("fuzz-afl-thesis");
    int code = 0;
    const std::string out = fuzz("printer3d_interp_thesis_parser", "printer3d-interp-thesis.yaml", "1500", dir, &code, "afl");
    EXPECT_EQ(code, 1) << out;
    EXPECT_NE(out.find("AFL++ with 1 instance(s)"), std::string::npos) << out;
    // A root cause per kind and shape of line: "timeout on 'G1 F X' lines".
    EXPECT_NE(out.find(". timeout on '"), std::string::npos) << out;
    EXPECT_NE(out.find("got no answer within 0.5 s"), std::string::npos) << out;
    EXPECT_TRUE(reports_a_crash(out)) << out;
    const auto [first, last] = features(out);
    EXPECT_GT(first, 0) << out;
    EXPECT_GT(last, first) << "coverage must grow over the run\n" << out;
    EXPECT_TRUE(std::filesystem::exists(dir / "out/afl/main/fuzzer_stats"));
    EXPECT_TRUE(std::filesystem::exists(dir / "out/findings/finding-1.vcd"));
}

// Seed 004's planted bug (digest §4: no bounds check on offset - angle): a
// target the arms reach but whose angle leaves a servo's 0..180 deg table.
// The bench sees it two ways: the move oracle (a G1 answered ok that needs a
// servo beyond its travel, parts/DeltaRobot) and, when the index lands
// outside all three tables, a pulse no table holds. The seed corpus is the
// thesis program's own moves (tests/fixtures/fuzz/firmware/delta-seed004-
// corpus: positionMatrix rows, digest §3/§8.4, in mm), all inside the
// travel. With seed 1 AFL++ finds it at its 4098th execution. The motion
// oracle on the board sees the same runs (the effector does not end on the
// target) and may be a reproducer's first finding, so the reproducers' runs
// (finding-N.txt, every finding of the run) are searched too.
std::string fuzz_delta(const std::string& elf, const std::string& runs, const std::filesystem::path& dir, int* exit_code) {
    const std::string command = std::string(::avrbench::test::cli()) + " fuzz --engine afl --elf " + test::firmware(elf) + " --board " +
                                test::source_path("bench/boards/delta-seed004.yaml") + " --corpus " +
                                test::source_path("tests/fixtures/fuzz/firmware/delta-seed004-corpus") + " --runs " + runs +
                                " --for " + std::to_string(kCampaignGuardSeconds) + "s --seed 1 --out " + (dir / "out").string();
    const auto r = test::run_command(command, dir, kCampaignGuardSeconds + 60);
    *exit_code = r.exit_code;
    return r.out + r.err;
}

TEST(Fuzz, AflFindsTheDeltaThesisOutOfTableAngle) {
    const auto dir = test::scratch_dir("fuzz-afl-delta-thesis");
    int code = 0;
    const std::string out = fuzz_delta("delta_thesis", "5000", dir, &code);
    EXPECT_EQ(code, 1) << out;
    std::string runs = out;
    for (const auto& entry : std::filesystem::directory_iterator(dir / "out/findings")) {
        if (entry.path().extension() == ".txt") runs += test::slurp(entry.path());
    }
    const bool beyond_travel = runs.find("robot: target-out-of-reach") != std::string::npos &&
                               runs.find(" beyond its servo's travel") != std::string::npos;
    const bool outside_tables = runs.find(": servo-pulse-out-of-range") != std::string::npos;
    EXPECT_TRUE(beyond_travel || outside_tables) << out;
    EXPECT_TRUE(std::filesystem::exists(dir / "out/findings/finding-1.gcode"));
}

TEST(Fuzz, AflFindsNothingInTheImprovedDelta) {
    const auto dir = test::scratch_dir("fuzz-afl-delta-improved");
    int code = 0;
    const std::string out = fuzz_delta("delta", "1000", dir, &code);
    EXPECT_EQ(code, 0) << out;
    EXPECT_NE(out.find("findings   0 distinct"), std::string::npos) << out;
}

TEST(Fuzz, AflFindsNothingInTheImprovedInterpolator) {
    const auto dir = test::scratch_dir("fuzz-afl-improved");
    int code = 0;
    const std::string out = fuzz("printer3d_interp", "printer3d-interp-alone.yaml", "1000", dir, &code, "afl");
    EXPECT_EQ(code, 0) << out;
    EXPECT_NE(out.find("findings   0 distinct"), std::string::npos) << out;
}

// ClusterFuzzLite runs a fuzzer as a bare binary: the target takes its
// settings from `<binary>.avrbench` beside it ($ORIGIN = its directory) when
// the environment has none. The AFL++ front end is used here because,
// started alone, it runs one input and aborts on a finding.
TEST(Fuzz, TargetReadsItsSettingsFromTheFileBesideIt) {
    namespace fs = std::filesystem;
    const auto dir = test::scratch_dir("fuzz-config");
    const fs::path target = dir / "fuzz_firmware_x";
    fs::copy_file(fs::path(::avrbench::test::cli()).parent_path() / "avrbench-fuzz-firmware-afl", target,
                  fs::copy_options::overwrite_existing);
    fs::copy_file(test::firmware("printer3d_interp_thesis_parser"), dir / "fw.elf", fs::copy_options::overwrite_existing);
    const std::string board = test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-thesis.yaml");
    // A lone NUL byte: the thesis parser never answers a line it does not understand (docs/FUZZING.md).
    std::ofstream(dir / "input", std::ios::binary) << std::string(1, '\0') << "\n";
    const std::string run = "env -u AVRBENCH_FUZZ_BOARD -u AVRBENCH_FUZZ_ELF " + target.string() + " " + (dir / "input").string();

    std::ofstream(target.string() + ".avrbench") << "# settings\nAVRBENCH_FUZZ_ELF=$ORIGIN/fw.elf\nAVRBENCH_FUZZ_BOARD=" << board << "\n";
    const auto found = test::run_command(run, dir, 60);
    EXPECT_NE(found.exit_code, 0) << found.out << found.err;
    EXPECT_NE(found.exit_code, 2) << found.err;
    EXPECT_NE(found.err.find("avrbench fuzz: FINDING"), std::string::npos) << found.err;
    EXPECT_NE(found.err.find("got no answer within 0.5 s"), std::string::npos) << found.err;

    std::ofstream(target.string() + ".avrbench") << "AVRBENCH_FUZZ_ELF=$ORIGIN/fw.elf\nno equals sign here\n";
    const auto bad = test::run_command(run, dir, 60);
    EXPECT_EQ(bad.exit_code, 2) << bad.out << bad.err;
    EXPECT_NE(bad.err.find("fuzz_firmware_x.avrbench:2: expected NAME=VALUE"), std::string::npos) << bad.err;
}

// A board of several MCUs: the fuzzed ELF runs on the serial port's MCU
// (seed 001's interpolator), the others get theirs from
// AVRBENCH_FUZZ_FIRMWARE and run in the board's lockstep. The carriages
// start at X 3.5 mm, Y 2.5 mm (bench/boards/printer3d-seed001.yaml); a full
// circle G2 I-5 J0 from there has its centre 5 mm to the left, and clockwise
// it goes down first: Y crosses 0 a twelfth of the way round (2.5 = 5 sin
// 30 deg; X is then at -1.5 + 5 cos 30 deg = 2.83 mm and only crosses 0 at
// 72.5 deg), past the travel's lower end: the drive board's motor must
// carry it there (the interpolator has no soft limits). The first finding
// ends the input, so Y's is the one reported. G1 X5 stays inside. M400
// keeps each input running until the move is done.
TEST(Fuzz, TargetRunsTheOtherMcusOfAMultiMcuBoard) {
    const auto dir = test::scratch_dir("fuzz-multi");
    const std::string drive = test::firmware("printer3d_drive");
    const std::string env = "env AVRBENCH_FUZZ_BOARD=printer3d-seed001 AVRBENCH_FUZZ_ELF=" + test::firmware("printer3d_interp") +
                            " 'AVRBENCH_FUZZ_FIRMWARE=drive_x=" + drive + ";drive_y=" + drive + ";drive_z=" + drive +
                            ";drive_e=" + drive + ";heater=" + test::firmware("printer3d_heater") + "' " +
                            (std::filesystem::path(::avrbench::test::cli()).parent_path() / "avrbench-fuzz-firmware-afl").string() + " ";
    std::ofstream(dir / "circle") << "G2 I-5 J0 F300\nM400\n";
    const auto circle = test::run_command(env + (dir / "circle").string(), dir, 60);
    EXPECT_NE(circle.exit_code, 0) << circle.err;
    EXPECT_NE(circle.err.find("FINDING"), std::string::npos) << circle.err;
    EXPECT_NE(circle.err.find("y: axis-out-of-travel"), std::string::npos) << circle.err;
    EXPECT_NE(circle.err.find("past the lower end of travel"), std::string::npos) << circle.err;
    std::ofstream(dir / "inside") << "G1 X5 F600\nM400\n";
    const auto inside = test::run_command(env + (dir / "inside").string(), dir, 60);
    EXPECT_EQ(inside.exit_code, 0) << inside.err;
    EXPECT_EQ(inside.err.find("FINDING"), std::string::npos) << inside.err;
}

// The board's motion oracle is one of the fuzz target's oracles: seed 001's
// DDA as printed (16-bit L: G1 X3 = 300 BLU gets L = 156, 1.56 mm) stops
// the line short, which only the oracle sees; the fixed DDA runs it clean.
TEST(Fuzz, TheMotionOracleJudgesEachInput) {
    const auto dir = test::scratch_dir("fuzz-motion");
    const std::string drive = test::firmware("printer3d_drive");
    const auto env = [&](const std::string& interp) {
        return "env AVRBENCH_FUZZ_BOARD=printer3d-seed001 AVRBENCH_FUZZ_ELF=" + test::firmware(interp) +
               " 'AVRBENCH_FUZZ_FIRMWARE=drive_x=" + drive + ";drive_y=" + drive + ";drive_z=" + drive + ";drive_e=" + drive +
               ";heater=" + test::firmware("printer3d_heater") + "' " +
               (std::filesystem::path(::avrbench::test::cli()).parent_path() / "avrbench-fuzz-firmware-afl").string() + " ";
    };
    std::ofstream(dir / "long_line") << "G1 X3 F600\nM400\n";
    const auto literal = test::run_command(env("printer3d_interp_thesis_dda") + (dir / "long_line").string(), dir, 60);
    EXPECT_NE(literal.exit_code, 0) << literal.err;
    EXPECT_NE(literal.err.find("motion: move-end-missed"), std::string::npos) << literal.err;
    EXPECT_NE(literal.err.find("line 1 'G1 X3 F600'"), std::string::npos) << literal.err;
    const auto fixed = test::run_command(env("printer3d_interp") + (dir / "long_line").string(), dir, 60);
    EXPECT_EQ(fixed.exit_code, 0) << fixed.err;
    EXPECT_EQ(fixed.err.find("FINDING"), std::string::npos) << fixed.err;
}

// The hang oracle of `--hang` (AVRBENCH_FUZZ_HANG=1): a line still
// unanswered when the input's bound ends. A 10 s dwell (G4 P10000) against a
// 2 s bound: the improved interpolator sends `echo:busy` every second, under
// the port's 2.5 s line timeout, so only the bound can see it.
TEST(Fuzz, ALineUnansweredAtTheBoundIsAHangOnlyWhenAsked) {
    const auto dir = test::scratch_dir("fuzz-hang");
    std::ofstream(dir / "dwell") << "G4 P10000\n";
    const std::string run = "AVRBENCH_FUZZ_BOUND=2 AVRBENCH_FUZZ_BOARD=" +
                            test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-alone.yaml") +
                            " AVRBENCH_FUZZ_ELF=" + test::firmware("printer3d_interp") + " " +
                            (std::filesystem::path(::avrbench::test::cli()).parent_path() / "avrbench-fuzz-firmware-afl").string() + " " +
                            (dir / "dwell").string();
    const auto plain = test::run_command("env AVRBENCH_FUZZ_HANG=0 " + run, dir, 60);
    EXPECT_EQ(plain.exit_code, 0) << plain.err;
    const auto hang = test::run_command("env AVRBENCH_FUZZ_HANG=1 " + run, dir, 60);
    EXPECT_NE(hang.exit_code, 0) << hang.err;
    EXPECT_NE(hang.err.find("hang: line 1 'G4 P10000' got no answer within the bound of 2 s"), std::string::npos) << hang.err;
    // Outside AFL (no __AFL_SHM_ID) a descriptor 199 left open by a shell
    // is not AFL's status pipe: still one run of the input.
    const auto fd199 = test::run_command("bash -c 'exec 199>/dev/null; env AVRBENCH_FUZZ_HANG=1 " + run + "'", dir, 60);
    EXPECT_NE(fd199.err.find("hang: line 1 'G4 P10000'"), std::string::npos) << fd199.err;
}

TEST(Fuzz, BadArgumentsAreOneLineWithExitCode2) {
    const auto dir = test::scratch_dir("fuzz-bad");
    const auto r = test::run_command(std::string(::avrbench::test::cli()) + " fuzz --elf /nonexistent.elf --board arduino-uno --for 5s", dir, 30);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("/nonexistent.elf"), std::string::npos) << r.err;
    const auto no_target = test::run_command("AVRBENCH_FUZZ_TARGET=/nonexistent " + std::string(::avrbench::test::cli()) +
                                                 " fuzz --elf " + test::firmware("printer3d_interp") + " --board " +
                                                 test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-alone.yaml") +
                                                 " --for 5s --out " + (dir / "out").string(),
                                             dir, 30);
    EXPECT_EQ(no_target.exit_code, 2) << no_target.out << no_target.err;
    EXPECT_NE(no_target.err.find("/nonexistent: cannot start"), std::string::npos) << no_target.err;
    const auto no_afl = test::run_command("PATH=/nonexistent " + std::string(::avrbench::test::cli()) + " fuzz --engine afl --elf " +
                                              test::firmware("printer3d_interp") + " --board " +
                                              test::source_path("tests/fixtures/fuzz/firmware/printer3d-interp-alone.yaml") +
                                              " --for 5s --out " + (dir / "out-afl").string(),
                                          dir, 30);
    EXPECT_EQ(no_afl.exit_code, 2) << no_afl.out << no_afl.err;
    EXPECT_NE(no_afl.err.find("afl-fuzz not found on PATH; install Debian's afl++"), std::string::npos) << no_afl.err;
    const auto bad_engine = test::run_command(std::string(::avrbench::test::cli()) + " fuzz --engine honggfuzz --elf x --board y", dir, 30);
    EXPECT_EQ(bad_engine.exit_code, 2) << bad_engine.out << bad_engine.err;
}

}  // namespace
}  // namespace avrbench
