#include "fuzz/campaign/Engines.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/Errors.hpp"
#include "core/UserStop.hpp"
#include "fuzz/campaign/Processes.hpp"

namespace avrbench::fuzz_campaign {

namespace fs = std::filesystem;

std::string budget_text(const FuzzCampaignOptions& args, double seconds) {
    char text[96];
    if (args.runs != 0) {
        std::snprintf(text, sizeof text, "%lu executions (at most %.0f s)", args.runs, seconds);
    } else {
        std::snprintf(text, sizeof text, "%.0f s", seconds);
    }
    return text;
}

Campaign libfuzzer_campaign(const FuzzCampaignOptions& args, const std::vector<std::string>& env, const fs::path& out,
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
            unsigned long runs = 0, cov = 0, features = 0, steady = 0, inputs = 0;
            if (std::sscanf(line.c_str(), "avrbench fuzz: %lu of %lu inputs ended repeating", &steady, &inputs) == 2) {
                campaign.ended_steady += steady;
                campaign.inputs_counted += inputs;
                continue;
            }
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
std::vector<std::string> afl_environment(const FuzzCampaignOptions& args, const std::vector<std::string>& env) {
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

Campaign afl_campaign(const FuzzCampaignOptions& args, const std::vector<std::string>& env, const fs::path& out,
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

}  // namespace avrbench::fuzz_campaign
