// `avrbench fuzz`: the front door to the firmware fuzz target
// (bench/fuzz/FirmwareTarget.hpp). Checks the board and firmware, writes a
// seed corpus and a G-code dictionary, runs the engine for the given wall
// time - Debian's libFuzzer, one job in one process or --jobs in its fork
// mode (fuzz_firmware.cpp), or Debian's
// AFL++ as one main and --jobs - 1 secondary instances on a shared sync
// directory (fuzz_firmware_afl.cpp); findings do not stop the campaign -
// then replays every reproducer once to name its finding, groups them, and
// records one run per distinct finding with `avrbench run` (summary + VCD).
#include "tools/FuzzCommand.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "debug/DebugRun.hpp"
#include "debug/RunViews.hpp"
#include "fuzz/FuzzFindings.hpp"
#include "core/Units.hpp"
#include "core/UserStop.hpp"
#include "stimulus/GcodeMutator.hpp"
#include "stimulus/UartHost.hpp"
#include "tools/Commands.hpp"
#include "tools/FirmwareArgs.hpp"
#include "run/Bench.hpp"
#include "run/BoardRun.hpp"

extern char** environ;

namespace avrbench {

namespace {

namespace fs = std::filesystem;

std::string self_dir() {
    std::error_code ec;
    const auto exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? std::string(".") : exe.parent_path().string();
}

// A helper program or library of `avrbench fuzz`: beside avrbench in a build
// tree, in <prefix>/libexec/avrbench where it is installed. "" if neither.
std::string find_helper(const std::string& name) {
    for (const fs::path& dir : {fs::path(self_dir()), fs::path(self_dir()) / ".." / "libexec" / "avrbench"}) {
        std::error_code ec;
        if (fs::is_regular_file(dir / name, ec)) return (dir / name).lexically_normal().string();
    }
    return "";
}

std::string find_target(const std::string& name, const char* override_variable) {
    if (const char* env = std::getenv(override_variable)) return env;
    if (std::string found = find_helper(name); !found.empty()) return found;
    throw BadInput(name + " not found beside avrbench (" + self_dir() + ") or in " + self_dir() +
                   "/../libexec/avrbench; the build makes it (bench/CMakeLists.txt; without Debian's libfuzzer-14-dev "
                   "only --engine afl is built)");
}

// A program on PATH (the AFL++ tools), or BadInput naming the package.
std::string find_on_path(const std::string& program, const std::string& package) {
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path != nullptr ? path : "/usr/bin");
    for (std::string dir; std::getline(dirs, dir, ':');) {
        const fs::path candidate = fs::path(dir.empty() ? "." : dir) / program;
        if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
    throw BadInput(program + " not found on PATH; install Debian's " + package + " (ci/setup lists it)");
}

// Starts argv with `env` added; stdout+stderr to `log`. Returns the pid.
pid_t spawn_logged(const std::vector<std::string>& argv, const std::vector<std::string>& env, const std::string& log) {
    // `env` replaces variables of the same name (getenv takes the first).
    const auto name_of = [](const std::string& entry) { return entry.substr(0, entry.find('=')); };
    std::vector<std::string> environment = env;
    for (char** e = environ; *e != nullptr; ++e) {
        const std::string entry(*e);
        const bool replaced = std::any_of(env.begin(), env.end(), [&](const std::string& mine) { return name_of(mine) == name_of(entry); });
        if (!replaced) environment.push_back(entry);
    }
    std::vector<char*> args, envp;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    for (const auto& e : environment) envp.push_back(const_cast<char*>(e.c_str()));
    envp.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw BadInput(argv[0] + ": cannot start (" + std::strerror(rc) + ")");
    return pid;
}

// Waits for the child, passing a Ctrl-C or SIGTERM of ours on to it (a
// fuzzing engine ends its campaign on SIGTERM): polled every 20 ms, so a
// stop is honoured within that, even one that came before the wait.
int wait_for(pid_t pid) {
    int status = 0;
    bool passed_on = false;
    for (;;) {
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid) return status;
        if (r < 0 && errno != EINTR) return status;
        if (!passed_on && user_stop_requested()) {
            ::kill(pid, SIGTERM);
            passed_on = true;
        }
        ::usleep(20'000);
    }
}

// Runs argv with `env` added; stdout+stderr to `log`. Returns the exit status.
int run_logged(const std::vector<std::string>& argv, const std::vector<std::string>& env, const std::string& log) {
    return wait_for(spawn_logged(argv, env, log));
}

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Lines the family's firmware answers with ok; the mutator builds on them.
std::vector<std::string> seed_lines(const std::string& family) {
    if (family == "grbl") return {"G21 G91\nG1 X1 Y1 F500\n", "$$\n", "G0 X2\nG4 P0.1\n", "?"};
    if (family == "marlin" || family == "teacup") return {"G1 X1 Y1 F500\n", "G01 X0.5 Y0 F10\n", "M105\n", "M114\n", "G92 X0 Y0\n"};
    return {"G1 X1 F500\n", "\n"};
}

// How a target runs one input: libFuzzer's needs -runs=1, AFL++'s runs its
// argument once when no fork server is listening.
struct Target {
    std::string path;
    bool libfuzzer = true;
};

// The finding an input gives when the target runs it once ("" for none).
std::string replay(const Target& target, const std::vector<std::string>& env, const fs::path& input) {
    const std::string log = input.string() + ".replay.txt";
    if (target.libfuzzer) {
        run_logged({target.path, "-runs=1", input.string()}, env, log);
    } else {
        run_logged({target.path, input.string()}, env, log);
    }
    const std::string output = slurp(log);
    fs::remove(log);
    const auto at = output.find("avrbench fuzz: FINDING");
    return at == std::string::npos ? "" : output.substr(at, output.find('\n', at) - at);
}

// Replays one root cause's minimisation may take (docs/FUZZING.md).
constexpr int kMinimizeReplays = 150;

// Shrinks `bytes` while the target still reports the same root cause:
// whole lines first, then single bytes (a greedy pass each; every try is a
// replay, so the tries are bounded, and so is the wall time: none after
// `deadline`).
std::string minimize(const Target& target, const std::vector<std::string>& env, const fs::path& scratch,
                     std::string bytes, const std::string& cause,
                     std::optional<std::chrono::steady_clock::time_point> deadline) {
    int budget = kMinimizeReplays;
    const auto same = [&](const std::string& candidate) {
        if (budget-- <= 0) return false;
        if (deadline && std::chrono::steady_clock::now() >= *deadline) {
            budget = 0;
            return false;
        }
        std::ofstream(scratch, std::ios::binary) << candidate;
        const std::string found = replay(target, env, scratch);
        return !found.empty() && finding_root_cause(found) == cause;
    };
    for (bool shrunk = true; shrunk && budget > 0;) {
        shrunk = false;
        for (std::size_t start = 0; start < bytes.size() && budget > 0;) {
            std::size_t end = bytes.find('\n', start);
            end = end == std::string::npos ? bytes.size() : end + 1;
            const std::string candidate = bytes.substr(0, start) + bytes.substr(end);
            if (same(candidate)) {
                bytes = candidate;
                shrunk = true;
            } else {
                start = end;
            }
        }
    }
    for (std::size_t i = 0; i < bytes.size() && budget > 0;) {
        const std::string candidate = bytes.substr(0, i) + bytes.substr(i + 1);
        if (same(candidate)) {
            bytes = candidate;
        } else {
            ++i;
        }
    }
    fs::remove(scratch);
    return bytes;
}

// What a campaign leaves for the replays, whichever engine ran it.
struct Campaign {
    Target target;
    unsigned long executions = 0;
    unsigned long coverage_start = 0, coverage_end = 0;
    unsigned long wall_timeouts = 0;  // AFL++ only
    std::vector<fs::path> artifacts;  // inputs the engine kept as crashes
    std::string artifact_dir;
};

// "60 s" or "20000 executions (at most 300 s)".
std::string budget_text(const FuzzArgs& args, double seconds) {
    char text[96];
    if (args.runs != 0) {
        std::snprintf(text, sizeof text, "%lu executions (at most %.0f s)", args.runs, seconds);
    } else {
        std::snprintf(text, sizeof text, "%.0f s", seconds);
    }
    return text;
}

Campaign libfuzzer_campaign(const FuzzArgs& args, const std::vector<std::string>& env, const fs::path& out,
                            const fs::path& corpus, const fs::path& findings, double seconds, const std::string& family) {
    Campaign campaign;
    campaign.target = {find_target("avrbench-fuzz-firmware", "AVRBENCH_FUZZ_TARGET"), true};
    campaign.artifact_dir = findings.string();
    // One job runs in this one process (the target keeps going after a
    // finding, AVRBENCH_FUZZ_CRASH_DIR): its course depends on --seed and
    // --runs, never on how fast the machine is. Several jobs: libFuzzer's
    // fork mode, which restarts a job after each crash.
    const bool in_process = args.jobs <= 1;
    std::vector<std::string> argv = {campaign.target.path,
                                     corpus.string(),
                                     "-max_total_time=" + std::to_string(static_cast<long>(seconds)),
                                     "-max_len=512",
                                     "-dict=" + (out / "gcode.dict").string(),
                                     "-artifact_prefix=" + findings.string() + "/",
                                     "-seed=" + std::to_string(args.seed),
                                     // The target runs in libFuzzer's process (a snapshot, not a
                                     // fork per input), where libFuzzer's memcmp/strcmp interceptors
                                     // would take the bench's own compares (the host reading answers)
                                     // for the firmware's and mutate towards them; the firmware's
                                     // compares are AVR instructions it cannot see.
                                     "-use_cmp=0",
                                     // Entropic's bookkeeping costs per feature per execution, and
                                     // an execution here has thousands (PC edges): measured, half of
                                     // each execution (docs/PERFORMANCE.md, "Fuzzing throughput").
                                     "-entropic=0"};
    if (in_process) {
        argv.push_back("-print_final_stats=1");
    } else {
        argv.insert(argv.end(), {"-fork=" + std::to_string(args.jobs), "-ignore_crashes=1"});
    }
    if (args.runs != 0) argv.push_back("-runs=" + std::to_string(args.runs));
    const std::string log = (out / "fuzz.log").string();
    // Kinds of finding already reported in this campaign: a job does not
    // stop (and restart) for a kind it or another job already found.
    const std::string seen = (out / "seen-findings.txt").string();
    fs::remove(seen);
    fs::remove(seen + ".hits");
    std::vector<std::string> campaign_env = env;
    campaign_env.push_back("AVRBENCH_FUZZ_SEEN=" + seen);
    if (in_process) campaign_env.push_back("AVRBENCH_FUZZ_CRASH_DIR=" + findings.string());
    std::printf("avrbench fuzz: %s on %s (family %s) for %s, %d job(s); libFuzzer log %s\n", args.elf.c_str(),
                args.board.c_str(), family.c_str(), budget_text(args, seconds).c_str(), std::max(1, args.jobs), log.c_str());
    std::fflush(stdout);
    run_logged(argv, campaign_env, log);

    // libFuzzer's status lines: "#<execs>: cov: .. ft: <features> .." in fork
    // mode, "#<execs>\t<EVENT> ft: <features> .." in one process (no "cov:":
    // the bench's code is not instrumented, the firmware's edges are features).
    std::vector<std::pair<unsigned long, unsigned long>> progress;
    {
        std::istringstream lines(slurp(log));
        std::string line;
        while (std::getline(lines, line)) {
            unsigned long runs = 0, cov = 0, features = 0;
            char event[16];
            if (std::sscanf(line.c_str(), "#%lu: cov: %lu ft: %lu", &runs, &cov, &features) == 3 ||
                std::sscanf(line.c_str(), "#%lu %15s ft: %lu", &runs, event, &features) == 3) {
                progress.emplace_back(runs, features);
            }
        }
    }
    if (progress.empty()) {
        if (user_stop_requested()) return campaign;  // stopped before its first status line
        throw BadInput(log + ": libFuzzer reported no progress (see the log)");
    }
    campaign.executions = progress.back().first;
    campaign.coverage_start = progress.front().second;
    campaign.coverage_end = progress.back().second;
    for (const auto& entry : fs::directory_iterator(findings)) {
        if (entry.path().filename().string().rfind("crash-", 0) == 0 && entry.path().extension().empty()) {
            campaign.artifacts.push_back(entry.path());
        }
    }
    return campaign;
}

// "key : value" from an AFL++ fuzzer_stats file (0 when absent).
unsigned long afl_stat(const fs::path& stats, const std::string& key) {
    std::istringstream lines(slurp(stats.string()));
    for (std::string line; std::getline(lines, line);) {
        const auto colon = line.find(':');
        if (colon == std::string::npos) continue;
        std::string name = line.substr(0, colon);
        name.erase(name.find_last_not_of(' ') + 1);
        if (name == key) return std::strtoul(line.c_str() + colon + 1, nullptr, 10);
    }
    return 0;
}

// The target's environment plus AFL++'s own settings.
std::vector<std::string> afl_environment(const FuzzArgs& args, const std::vector<std::string>& env) {
    std::vector<std::string> afl_env = env;
    afl_env.insert(afl_env.end(), {"AFL_SKIP_CPUFREQ=1", "AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1", "AFL_NO_UI=1",
                                   "AFL_NO_AFFINITY=1", "AFL_FORKSRV_INIT_TMOUT=60000",
                                   // AFL++ refuses sanitizer settings that do not abort (a sanitized build of the bench)
                                   "ASAN_OPTIONS=abort_on_error=1:symbolize=0:detect_leaks=0",
                                   "UBSAN_OPTIONS=halt_on_error=1:abort_on_error=1:symbolize=0",
                                   "LSAN_OPTIONS=symbolize=0"});
    if (!args.raw) {
        // The structure-aware G-code mutator (bench/fuzz/afl_gcode_mutator.cpp) beside AFL++'s own havoc.
        const std::string mutator = find_helper("libavrbench-afl-gcode-mutator.so");
        if (!mutator.empty()) afl_env.push_back("AFL_CUSTOM_MUTATOR_LIBRARY=" + mutator);
    }
    return afl_env;
}

// Why AFL++ gave up: its "PROGRAM ABORT" line, without the colour codes around it.
std::string afl_abort_reason(const std::string& log_path) {
    std::string why = "see the log";
    std::istringstream lines(slurp(log_path));
    for (std::string line; std::getline(lines, line);) {
        if (line.find("PROGRAM ABORT") == std::string::npos) continue;
        why.clear();
        for (std::size_t i = 0; i < line.size(); ++i) {
            if (line[i] == '\x1b') {
                while (i < line.size() && !std::isalpha(static_cast<unsigned char>(line[i]))) ++i;
                continue;
            }
            why += line[i];
        }
    }
    return why;
}

// Executions, coverage, timeouts and crash inputs of every instance.
void collect_afl_results(Campaign& campaign, const fs::path& sync) {
    campaign.coverage_end = afl_stat(sync / "main" / "fuzzer_stats", "edges_found");  // main imports the others' finds
    campaign.artifact_dir = (sync / "*" / "crashes").string();
    for (const auto& instance : fs::directory_iterator(sync)) {
        campaign.executions += afl_stat(instance.path() / "fuzzer_stats", "execs_done");
        campaign.wall_timeouts += afl_stat(instance.path() / "fuzzer_stats", "saved_hangs");
        if (!fs::is_directory(instance.path() / "crashes")) continue;
        for (const auto& entry : fs::directory_iterator(instance.path() / "crashes")) {
            if (entry.path().filename().string().rfind("id:", 0) == 0) campaign.artifacts.push_back(entry.path());
        }
    }
}

Campaign afl_campaign(const FuzzArgs& args, const std::vector<std::string>& env, const fs::path& out,
                      const fs::path& corpus, double seconds, double bound_s, const std::string& family) {
    Campaign campaign;
    campaign.target = {find_target("avrbench-fuzz-firmware-afl", "AVRBENCH_FUZZ_AFL_TARGET"), false};
    const std::string afl_fuzz = find_on_path("afl-fuzz", "afl++");
    const std::string afl_showmap = find_on_path("afl-showmap", "afl++");
    const fs::path sync = out / "afl";
    fs::remove_all(sync);  // AFL++ refuses to resume into a finished directory without -i -
    // Wall-clock limit per input, generous: an input may take bound_s of
    // simulated time, and the slowest firmware here runs ~10x real time.
    const long timeout_ms = 2000 + static_cast<long>(bound_s * 1000);
    const std::vector<std::string> afl_env = afl_environment(args, env);
    const int jobs = std::max(1, args.jobs);
    std::printf("avrbench fuzz: %s on %s (family %s) for %s, AFL++ with %d instance(s) on %s; logs %s/*.log\n",
                args.elf.c_str(), args.board.c_str(), family.c_str(), budget_text(args, seconds).c_str(), jobs,
                sync.string().c_str(), out.string().c_str());
    std::fflush(stdout);
    std::vector<pid_t> instances;
    for (int i = 0; i < jobs; ++i) {
        const std::string name = i == 0 ? "main" : "secondary-" + std::to_string(i);
        std::vector<std::string> argv = {afl_fuzz,
                                         "-i", corpus.string(),
                                         "-o", sync.string(),
                                         i == 0 ? "-M" : "-S", name,
                                         "-V", std::to_string(static_cast<long>(seconds)),
                                         "-t", std::to_string(timeout_ms),
                                         "-s", std::to_string(args.seed + static_cast<unsigned>(i)),
                                         "-x", (out / "gcode.dict").string(),
                                         "--", campaign.target.path, "@@"};
        if (args.runs != 0) {
            // Each instance's share of the executions (AFL++'s -E).
            const unsigned long share = std::max(1ul, args.runs / static_cast<unsigned long>(jobs));
            argv.insert(argv.begin() + 1, {"-E", std::to_string(share)});
        }
        instances.push_back(spawn_logged(argv, afl_env, (out / ("afl-" + name + ".log")).string()));
    }
    // Coverage of the seeds alone, with AFL++'s own count, while the instances start.
    const fs::path seed_map = out / "seed-coverage.txt";
    run_logged({afl_showmap, "-C", "-i", corpus.string(), "-o", seed_map.string(), "-t", std::to_string(timeout_ms),
                "--", campaign.target.path, "@@"},
               afl_env, (out / "afl-showmap.log").string());
    {
        std::ifstream map(seed_map);
        for (std::string line; std::getline(map, line);) ++campaign.coverage_start;
    }
    bool all_ran = true;
    for (pid_t pid : instances) {
        const int status = wait_for(pid);
        all_ran = all_ran && WIFEXITED(status) && WEXITSTATUS(status) == 0;
    }
    if (!fs::exists(sync / "main" / "fuzzer_stats")) {
        if (user_stop_requested()) return campaign;
        throw BadInput((out / "afl-main.log").string() + ": AFL++ did not start fuzzing (" +
                       afl_abort_reason((out / "afl-main.log").string()) + ")");
    }
    if (!all_ran) std::printf("  (an AFL++ instance ended with an error; see %s/afl-*.log)\n", out.string().c_str());
    collect_afl_results(campaign, sync);
    return campaign;
}

// Which ELF runs where: the fuzzed one on the MCU of the board's serial
// port, the others from --firmware; and the port's firmware family.
struct FuzzFirmware {
    std::string family;
    std::string other_firmware;             // "mcu=elf;mcu=elf" for the target
    std::vector<std::string> run_firmware;  // `run ELF --firmware ...` as the recorded runs give it
};

FuzzFirmware fuzz_firmware(const FuzzArgs& args) {
    FuzzFirmware fw;
    // BadInput for a bad board or ELF, as `run` says it.
    BoardSpec spec = load_board_file(args.board);
    if (spec.serial_port_mcu().empty()) throw BadInput(args.board + ": has no serial port (a serial_host part) for the fuzz input");
    std::map<std::string, std::string> firmware = firmware_assignments(args.firmware);
    for (const auto& [mcu, elf] : firmware) fw.other_firmware += (fw.other_firmware.empty() ? "" : ";") + mcu + "=" + elf;
    firmware[spec.serial_port_mcu()] = args.elf;
    // run's ELF goes to the board's first MCU, which need not be the serial port's.
    const std::string first_mcu = spec.mcus.front().name;
    fw.run_firmware.push_back(firmware.count(first_mcu) != 0 ? firmware[first_mcu] : args.elf);
    for (const auto& [mcu, elf] : firmware) {
        if (mcu != first_mcu) fw.run_firmware.insert(fw.run_firmware.end(), {"--firmware", mcu + "=" + elf});
    }
    Bench bench(std::move(spec), firmware);
    fw.family = args.family.empty() ? bench.serial_port().protocol().family : args.family;
    (void)parse_firmware_family(fw.family, "--family");
    return fw;
}

// What the reproducers' runs need besides the campaign.
struct FindingsRun {
    const FuzzArgs& args;
    const std::vector<std::string>& run_firmware;
    const std::string& family;
    const fs::path& findings;
    double bound_s;
    // Minimisation stops here (a campaign bounded by --for alone); none
    // with --runs, where the replays' count bounds it.
    std::optional<std::chrono::steady_clock::time_point> deadline;
    fs::path hits;  // the target's count of inputs per root cause ("": none)
};

// The target's <seen>.hits: one line per input that hit a root cause.
std::map<std::string, std::size_t> hits_per_cause(const fs::path& hits) {
    std::map<std::string, std::size_t> count;
    std::ifstream in(hits);
    for (std::string line; std::getline(in, line);) ++count[line];
    return count;
}

// Replays each reproducer once (the target prints the finding and aborts),
// groups them, minimizes the shortest of each group and records its run.
// Exit code: 1 when something was found.
int report_findings(Campaign& campaign, const std::vector<std::string>& env, const FindingsRun& how) {
    const FuzzArgs& args = how.args;
    const auto& run_firmware = how.run_firmware;
    const std::string& family = how.family;
    const fs::path& findings = how.findings;
    const double bound_s = how.bound_s;
    const Target& target = campaign.target;
    if (user_stop_requested()) {
        // Stopped (Ctrl-C, SIGTERM): what the engine kept stays for a later
        // look; nothing is replayed, so the stop is honoured at once.
        std::printf("  interrupted: %zu reproducers kept in %s, not replayed (replay one with --replay FILE)\n",
                    campaign.artifacts.size(), campaign.artifact_dir.c_str());
        return 130;
    }
    std::map<std::string, std::vector<fs::path>> by_cause;
    std::map<std::string, std::string> example;  // root cause -> the first replay's whole line
    std::size_t not_reproduced = 0;
    std::vector<fs::path>& artifacts = campaign.artifacts;
    std::sort(artifacts.begin(), artifacts.end());
    for (const auto& artifact : artifacts) {
        const std::string line = replay(target, env, artifact);
        if (line.empty()) {
            ++not_reproduced;  // e.g. libFuzzer's own crash report of a job, or a flaky bench: kept, not listed
            continue;
        }
        const std::string cause = finding_root_cause(line);
        by_cause[cause].push_back(artifact);
        example.emplace(cause, line.substr(line.find("instructions: ") + 14));
    }
    const auto hits = how.hits.empty() ? std::map<std::string, std::size_t>{} : hits_per_cause(how.hits);
    std::printf("  findings   %zu distinct root causes (%zu reproducers in %s", by_cause.size(), artifacts.size(),
                campaign.artifact_dir.c_str());
    if (not_reproduced != 0) std::printf("; %zu did not reproduce on replay", not_reproduced);
    std::printf(")\n");
    int index = 0;
    for (auto& [cause, files] : by_cause) {
        // The shortest reproducer of each, minimized (the same root cause
        // must remain), recorded as a run with its VCD.
        const fs::path shortest = *std::min_element(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
            return fs::file_size(a) < fs::file_size(b);
        });
        const std::string base = (findings / ("finding-" + std::to_string(++index))).string();
        const bool out_of_time = how.deadline && std::chrono::steady_clock::now() >= *how.deadline;
        const std::string minimal = minimize(target, env, base + ".try", slurp(shortest.string()), cause, how.deadline);
        std::ofstream(base + ".gcode", std::ios::binary) << minimal;
        // Replayed the way the fuzz target sent it: lines through the port's
        // host, bytes that are not text included.
        std::vector<std::string> run = {self_dir() + "/avrbench", "run"};
        run.insert(run.end(), run_firmware.begin(), run_firmware.end());
        run.insert(run.end(), {"--board", args.board, "--for", std::to_string(bound_s + 1) + "s", "--vcd", base + ".vcd"});
        if (args.raw) {
            // The bytes from power-on (the fuzz target sent them after its boot time; --uart-in holds
            // them until the firmware enables its receiver).
            run.insert(run.end(), {"--uart-in", base + ".gcode"});
        } else {
            run.insert(run.end(), {"--family", family, "--gcode", base + ".gcode", "--gcode-bytes"});
        }
        run_logged(run, {}, base + ".txt");
        const auto hit = hits.find(cause);
        const std::size_t inputs = hit != hits.end() ? hit->second : files.size();
        std::printf("    %d. %s (%zu input%s hit it)\n       e.g. %s\n       %s: %zu bytes (from %ju), %s.gcode; its run: %s.txt, %s.vcd\n",
                    index, cause.c_str(), inputs, inputs == 1 ? "" : "s", example[cause].c_str(),
                    out_of_time ? "not minimized (the --for budget was spent)" : "minimized", minimal.size(),
                    static_cast<std::uintmax_t>(fs::file_size(shortest)), base.c_str(), base.c_str(), base.c_str());
    }
    return by_cause.empty() ? 0 : 1;
}

}  // namespace

// --replay: one input on the board as the fuzz target sends it (the lines
// byte for byte through the port's host, or --raw's bytes from power-on),
// for --bound plus a second, with avr-gdb when --gdb is given. Exit code as
// `run --strict`'s: every finding the target would report fails it.
int replay_command(const FuzzArgs& args) {
    const FuzzFirmware fw = fuzz_firmware(args);
    const double bound_s = seconds_from_ps(parse_duration_ps(args.bound, "--bound"));
    BoardRunOptions o;
    o.board = args.board;
    o.elf = fw.run_firmware.front();
    for (std::size_t i = 1; i + 1 < fw.run_firmware.size(); i += 2) {
        const std::string& item = fw.run_firmware[i + 1];
        o.firmware[item.substr(0, item.find('='))] = item.substr(item.find('=') + 1);
    }
    o.duration_ps = ps_from_seconds(bound_s + 1, "--bound");
    o.read_uart_input = [](const std::string& path) { return read_input_file(path, "--replay", kMaxUartInputBytes); };
    if (args.raw) {
        o.uart_in.push_back({"", args.replay});
    } else {
        BoardRunOptions::GcodeJob job;
        job.path = args.replay;
        job.raw_bytes = true;
        job.family = fw.family;
        o.gcode = job;
    }
    o.on_announce = [](const std::string& line) { std::printf("%s\n", line.c_str()); };
    if (auto debug = debug_options(DebugArgs{args.gdb, args.break_at_finding, args.break_at, args.break_at_cycle})) {
        Debugger debugger(*debug);
        const auto run = run_board_debugged(o, debugger);
        for (const std::string& line : run->summary()) std::printf("%s\n", line.c_str());
        return exit_code(debugged_verdict(debugger, run->verdict(true)));
    }
    BoardRun run(o);
    run.run();
    for (const std::string& line : run.summary()) std::printf("%s\n", line.c_str());
    return exit_code(run.verdict(true));
}

namespace {

// Every argument checked before any work (a file written, an engine started).
FuzzArgs checked(FuzzArgs args) {
    if (!args.runs_text.empty()) {
        const std::string& t = args.runs_text;
        const bool digits = !t.empty() && t.size() <= 13 && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
        args.runs = digits ? std::stoul(t) : 0;
        constexpr unsigned long kMostRuns = 1'000'000'000'000ul;
        if (!digits || args.runs < 1 || args.runs > kMostRuns) {
            throw BadInput("--runs: '" + t + "' is not a count of executions from 1 to 10^12");
        }
    }
    if (args.jobs < 1 || args.jobs > 64) throw BadInput("--jobs: " + std::to_string(args.jobs) + " is not from 1 to 64");
    const Picoseconds bound = parse_duration_ps(args.bound, "--bound");
    if (bound < kPsPerMs) throw BadInput("--bound: '" + args.bound + "' is under 1 ms: an input needs simulated time to run");
    if (args.replay.empty()) {
        // --out: a writable folder, or a new one in a writable folder.
        std::error_code ec;
        const fs::path out = args.out;
        const auto writable = [](const fs::path& folder) { return ::access(folder.c_str(), W_OK | X_OK) == 0; };
        if (fs::exists(fs::symlink_status(out, ec))) {
            if (!fs::is_directory(fs::status(out, ec))) throw BadInput("--out: " + args.out + " is not a folder (the campaign writes a folder there)");
            if (!writable(out)) throw BadInput("--out: the folder " + args.out + " is not writable");
        } else {
            fs::path parent = out.parent_path();
            if (parent.empty()) parent = ".";
            if (!fs::is_directory(parent, ec) || !writable(parent)) {
                throw BadInput("--out: cannot make the folder " + args.out + " (" + parent.string() + " is not a writable folder)");
            }
        }
        if (!args.corpus.empty()) {
            if (!fs::is_directory(args.corpus, ec)) throw BadInput("--corpus: " + args.corpus + " is not a folder");
        }
    }
    return args;
}

}  // namespace

int fuzz_command(const FuzzArgs& raw_args) {
    const FuzzArgs args = checked(raw_args);
    if (!args.replay.empty()) return replay_command(args);
    if (!args.gdb.empty() || args.break_at_finding || !args.break_at.empty() || !args.break_at_cycle.empty()) {
        throw BadInput("--gdb and the --break-at options need --replay FILE (a campaign runs without a debugger)");
    }
    const double seconds = seconds_from_ps(parse_duration_ps(args.duration, "--for"));
    const double bound_s = seconds_from_ps(parse_duration_ps(args.bound, "--bound"));
    if (seconds < 1) throw BadInput("--for: fuzz for at least 1s");
    const FuzzFirmware fw = fuzz_firmware(args);
    const std::string& family = fw.family;
    const std::vector<std::string>& run_firmware = fw.run_firmware;
    const std::string& other_firmware = fw.other_firmware;
    const fs::path out = args.out;
    const fs::path corpus = out / "corpus", findings = out / "findings";
    {
        std::error_code ec;
        fs::create_directories(corpus, ec);
        if (!ec) fs::create_directories(findings, ec);
        if (ec) throw BadInput("--out: cannot make " + corpus.string() + " and " + findings.string() + ": " + ec.message());
    }
    // Raw: a few bytes of seed 002's record protocol (M30, a G00 header);
    // coverage finds the rest.
    const std::vector<std::string> seeds =
        args.raw ? std::vector<std::string>{std::string("\x3b", 1), std::string("\x00\x00\x10\x00\x10\x40\x40\x05", 8)}
                 : seed_lines(family);
    for (std::size_t i = 0; i < seeds.size(); ++i) std::ofstream(corpus / ("seed-" + std::to_string(i))) << seeds[i];
    if (!args.corpus.empty()) {
        std::error_code ec;
        if (!fs::is_directory(args.corpus, ec)) throw BadInput(args.corpus + ": --corpus is not a directory");
        std::size_t copied = 0;
        for (const auto& entry : fs::directory_iterator(args.corpus, ec)) {
            // A link that loops or leads nowhere is skipped; files are copied.
            std::error_code file_ec;
            if (!entry.is_regular_file(file_ec) || file_ec) continue;
            fs::copy_file(entry.path(), corpus / ("user-" + entry.path().filename().string()), fs::copy_options::overwrite_existing,
                          file_ec);
            if (file_ec) throw BadInput("--corpus: " + entry.path().string() + ": cannot copy (" + file_ec.message() + ")");
            ++copied;
        }
        if (ec) throw BadInput("--corpus: " + args.corpus + ": cannot read (" + ec.message() + ")");
        if (copied == 0) throw BadInput(args.corpus + ": --corpus holds no files");
    }
    {
        std::ofstream dict(out / "gcode.dict");
        for (const auto& word : gcode_dictionary()) dict << '"' << word << "\"\n";  // libFuzzer's and AFL's format
    }
    std::vector<std::string> env = {"AVRBENCH_FUZZ_BOARD=" + args.board, "AVRBENCH_FUZZ_ELF=" + args.elf,
                                          "AVRBENCH_FUZZ_BOUND=" + std::to_string(bound_s), "AVRBENCH_FUZZ_FAMILY=" + family,
                                          std::string("AVRBENCH_FUZZ_RAW=") + (args.raw ? "1" : "0"),
                                          "AVRBENCH_FUZZ_BOOT=" + std::to_string(seconds_from_ps(parse_duration_ps(args.boot, "--boot"))),
                                          "AVRBENCH_FUZZ_FIRMWARE=" + other_firmware,
                                          std::string("AVRBENCH_FUZZ_HANG=") + (args.hang ? "1" : "0")};
    const auto started = std::chrono::steady_clock::now();
    // --for bounds the whole campaign: the engine gets four fifths of it and
    // the replays, minimisation and recorded runs the rest, stopping at the
    // end. With --runs the executions bound the engine, and each root
    // cause's minimisation takes at most kMinimizeReplays replays, on any
    // machine the same.
    std::optional<std::chrono::steady_clock::time_point> deadline;
    double engine_s = seconds;
    if (args.runs == 0) {
        engine_s = std::max(1.0, seconds * 0.8);
        deadline = started + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
        std::printf("avrbench fuzz: %.0f s in all: fuzzing %.0f s, then replaying and minimising what it found until the end\n",
                    seconds, engine_s);
    } else {
        std::printf("avrbench fuzz: minimising takes at most %d replays per root cause after the %lu executions\n",
                    kMinimizeReplays, args.runs);
    }
    Campaign campaign = args.engine == "afl" ? afl_campaign(args, env, out, corpus, engine_s, bound_s, family)
                                             : libfuzzer_campaign(args, env, out, corpus, findings, engine_s, family);
    const double campaign_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::printf("  executions %lu in %.1f s (%.0f per second)\n", campaign.executions, campaign_s,
                campaign_s > 0 ? static_cast<double>(campaign.executions) / campaign_s : 0.0);
    std::printf("  coverage   firmware edge %s %lu at the start, %lu at the end\n",
                campaign.target.libfuzzer ? "features" : "tuples (AFL++'s edges)", campaign.coverage_start,
                campaign.coverage_end);
    if (campaign.wall_timeouts != 0) {
        std::printf("  timeouts   %lu inputs ran past AFL++'s wall-clock limit (out/afl/*/hangs; not findings: "
                    "the simulated bound is the hang oracle)\n",
                    campaign.wall_timeouts);
    }

    const fs::path hits = args.engine == "afl" ? fs::path() : out / "seen-findings.txt.hits";
    return report_findings(campaign, env, FindingsRun{args, run_firmware, family, findings, bound_s, deadline, hits});
}

}  // namespace avrbench
