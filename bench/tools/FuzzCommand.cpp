// `avrbench fuzz`: the front door to the firmware fuzz target
// (bench/fuzz/fuzz_firmware.cpp, Debian's libFuzzer). Checks the board and
// firmware, writes a seed corpus and a G-code dictionary, runs libFuzzer in
// fork mode for the given wall time (findings do not stop the campaign),
// then replays every reproducer once to name its finding, groups them, and
// records one run per distinct finding with `avrbench run` (summary + VCD).
#include "tools/FuzzCommand.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fcntl.h>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/Errors.hpp"
#include "fuzz/FuzzFindings.hpp"
#include "core/Units.hpp"
#include "stimulus/GcodeMutator.hpp"
#include "stimulus/UartHost.hpp"
#include "verify/Bench.hpp"

extern char** environ;

namespace avrbench {

namespace {

namespace fs = std::filesystem;

std::string self_dir() {
    std::error_code ec;
    const auto exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? std::string(".") : exe.parent_path().string();
}

std::string find_target() {
    if (const char* env = std::getenv("AVRBENCH_FUZZ_TARGET")) return env;
    const std::string beside = self_dir() + "/avrbench-fuzz-firmware";
    if (fs::exists(beside)) return beside;
    throw BadInput("avrbench-fuzz-firmware not found beside avrbench (" + beside +
                   "); it is built with Debian's libFuzzer (libfuzzer-14-dev, ci/setup)");
}

// Runs argv with `env` added; stdout+stderr to `log`. Returns the exit status.
int run_logged(const std::vector<std::string>& argv, const std::vector<std::string>& env, const std::string& log) {
    std::vector<std::string> environment;
    for (char** e = environ; *e != nullptr; ++e) environment.emplace_back(*e);
    environment.insert(environment.end(), env.begin(), env.end());
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
    int status = 0;
    while (waitpid(pid, &status, 0) < 0) {
    }
    return status;
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

// The finding an input gives when the target runs it once ("" for none).
std::string replay(const std::string& target, const std::vector<std::string>& env, const fs::path& input) {
    const std::string log = input.string() + ".replay.txt";
    run_logged({target, "-runs=1", input.string()}, env, log);
    const std::string output = slurp(log);
    fs::remove(log);
    const auto at = output.find("avrbench fuzz: FINDING");
    return at == std::string::npos ? "" : output.substr(at, output.find('\n', at) - at);
}

// Shrinks `bytes` while the target still reports the same kind of finding:
// whole lines first, then single bytes (a greedy pass each; every try is a
// replay, so the tries are bounded).
std::string minimize(const std::string& target, const std::vector<std::string>& env, const fs::path& scratch,
                     std::string bytes, const std::string& kind) {
    int budget = 150;
    const auto same = [&](const std::string& candidate) {
        if (budget-- <= 0) return false;
        std::ofstream(scratch, std::ios::binary) << candidate;
        const std::string found = replay(target, env, scratch);
        return !found.empty() && finding_kind(found) == kind;
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

}  // namespace

int fuzz_command(const FuzzArgs& args) {
    const double seconds = seconds_from_ps(parse_duration_ps(args.duration, "--for"));
    const double bound_s = seconds_from_ps(parse_duration_ps(args.bound, "--bound"));
    if (seconds < 1) throw BadInput("--for: fuzz for at least 1s");
    std::string family;
    {
        Bench bench(args.board, args.elf);  // BadInput for a bad board or ELF, as `run` says it
        if (bench.board().mcus().size() != 1) {
            throw BadInput(args.board + ": has " + std::to_string(bench.board().mcus().size()) +
                           " MCUs; avrbench fuzz steps boards with one MCU");
        }
        family = args.family.empty() ? bench.serial_decl().family : args.family;
        (void)parse_firmware_family(family, "--family");
    }
    const std::string target = find_target();
    const fs::path out = args.out;
    const fs::path corpus = out / "corpus", findings = out / "findings";
    fs::create_directories(corpus);
    fs::create_directories(findings);
    // Raw: a few bytes of seed 002's record protocol (M30, a G00 header);
    // coverage finds the rest.
    const std::vector<std::string> seeds =
        args.raw ? std::vector<std::string>{std::string("\x3b", 1), std::string("\x00\x00\x10\x00\x10\x40\x40\x05", 8)}
                 : seed_lines(family);
    for (std::size_t i = 0; i < seeds.size(); ++i) std::ofstream(corpus / ("seed-" + std::to_string(i))) << seeds[i];
    {
        std::ofstream dict(out / "gcode.dict");
        for (const auto& word : gcode_dictionary()) dict << '"' << word << "\"\n";
    }
    std::vector<std::string> env = {"AVRBENCH_FUZZ_BOARD=" + args.board, "AVRBENCH_FUZZ_ELF=" + args.elf,
                                          "AVRBENCH_FUZZ_BOUND=" + std::to_string(bound_s), "AVRBENCH_FUZZ_FAMILY=" + family,
                                          std::string("AVRBENCH_FUZZ_RAW=") + (args.raw ? "1" : "0"),
                                          "AVRBENCH_FUZZ_BOOT=" + std::to_string(seconds_from_ps(parse_duration_ps(args.boot, "--boot")))};
    std::vector<std::string> argv = {target,
                                     corpus.string(),
                                     "-max_total_time=" + std::to_string(static_cast<long>(seconds)),
                                     "-fork=" + std::to_string(std::max(1, args.jobs)),
                                     "-ignore_crashes=1",
                                     "-max_len=512",
                                     "-dict=" + (out / "gcode.dict").string(),
                                     "-artifact_prefix=" + findings.string() + "/",
                                     "-seed=" + std::to_string(args.seed)};
    const std::string log = (out / "fuzz.log").string();
    // Kinds of finding already reported in this campaign: a job does not
    // stop (and restart) for a kind it or another job already found.
    const std::string seen = (out / "seen-findings.txt").string();
    fs::remove(seen);
    std::vector<std::string> campaign_env = env;
    campaign_env.push_back("AVRBENCH_FUZZ_SEEN=" + seen);
    std::printf("avrbench fuzz: %s on %s (family %s) for %.0f s, %d job(s); libFuzzer log %s\n", args.elf.c_str(),
                args.board.c_str(), family.c_str(), seconds, std::max(1, args.jobs), log.c_str());
    std::fflush(stdout);
    run_logged(argv, campaign_env, log);

    // libFuzzer's fork-mode status lines: "#<execs>: cov: .. ft: <features> ..".
    std::vector<std::pair<unsigned long, unsigned long>> progress;
    {
        std::istringstream lines(slurp(log));
        std::string line;
        while (std::getline(lines, line)) {
            unsigned long runs = 0, cov = 0, features = 0;
            if (std::sscanf(line.c_str(), "#%lu: cov: %lu ft: %lu", &runs, &cov, &features) == 3) {
                progress.emplace_back(runs, features);
            }
        }
    }
    if (progress.empty()) throw BadInput(log + ": libFuzzer reported no progress (see the log)");
    const unsigned long execs = progress.back().first;
    std::printf("  executions %lu (%.0f per second)\n", execs, static_cast<double>(execs) / seconds);
    std::printf("  coverage   firmware edge features %lu at the start, %lu at the end\n", progress.front().second,
                progress.back().second);

    // Replay each reproducer once: the target prints the finding and aborts.
    std::map<std::string, std::vector<fs::path>> by_finding;
    std::map<std::string, std::string> example;  // finding -> the first replay's whole line
    std::size_t not_reproduced = 0;
    std::vector<fs::path> artifacts;
    for (const auto& entry : fs::directory_iterator(findings)) {
        if (entry.path().filename().string().rfind("crash-", 0) == 0 && entry.path().extension().empty()) {
            artifacts.push_back(entry.path());
        }
    }
    std::sort(artifacts.begin(), artifacts.end());
    for (const auto& artifact : artifacts) {
        const std::string line = replay(target, env, artifact);
        if (line.empty()) {
            ++not_reproduced;  // e.g. libFuzzer's own crash report of a job, or a flaky bench: kept, not listed
            continue;
        }
        const std::string finding = finding_kind(line);
        by_finding[finding].push_back(artifact);
        example.emplace(finding, line.substr(line.find("instructions: ") + 14));
    }
    std::printf("  findings   %zu distinct (%zu reproducers in %s", by_finding.size(), artifacts.size(),
                findings.string().c_str());
    if (not_reproduced != 0) std::printf("; %zu did not reproduce on replay", not_reproduced);
    std::printf(")\n");
    int index = 0;
    for (auto& [finding, files] : by_finding) {
        // The shortest reproducer of each, minimized (the same kind of
        // finding must remain), recorded as a run with its VCD.
        const fs::path shortest = *std::min_element(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
            return fs::file_size(a) < fs::file_size(b);
        });
        const std::string base = (findings / ("finding-" + std::to_string(++index))).string();
        const std::string minimal = minimize(target, env, base + ".try", slurp(shortest.string()), finding);
        std::ofstream(base + ".gcode", std::ios::binary) << minimal;
        // Replayed the way the fuzz target sent it: lines through the port's
        // host, bytes that are not text included.
        std::vector<std::string> run = {self_dir() + "/avrbench", "run", args.elf, "--board", args.board, "--for",
                                        std::to_string(bound_s + 1) + "s", "--vcd", base + ".vcd"};
        if (args.raw) {
            // The bytes from power-on (the fuzz target sent them after its boot time; --uart-in holds
            // them until the firmware enables its receiver).
            run.insert(run.end(), {"--uart-in", base + ".gcode"});
        } else {
            run.insert(run.end(), {"--family", family, "--gcode", base + ".gcode", "--gcode-bytes"});
        }
        run_logged(run, {}, base + ".txt");
        std::printf("    %d. %s (%zu reproducers)\n       e.g. %s\n       minimized: %zu bytes (from %ju), %s.gcode; its run: %s.txt, %s.vcd\n",
                    index, finding.c_str(), files.size(), example[finding].c_str(), minimal.size(),
                    static_cast<std::uintmax_t>(fs::file_size(shortest)), base.c_str(), base.c_str(), base.c_str());
    }
    return by_finding.empty() ? 0 : 1;
}

}  // namespace avrbench
