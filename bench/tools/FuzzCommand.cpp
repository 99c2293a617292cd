// `avrbench fuzz`: its arguments checked and handed to the campaign
// (fuzz/campaign/FuzzCampaign.hpp), or one input replayed (--replay), under
// avr-gdb when asked.
#include "tools/FuzzCommand.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/Errors.hpp"
#include "core/Units.hpp"
#include "debug/DebugRun.hpp"
#include "debug/RunViews.hpp"
#include "fuzz/campaign/FuzzCampaign.hpp"
#include "tools/Commands.hpp"
#include "tools/FirmwareArgs.hpp"

namespace avrbench {
namespace {

namespace fs = std::filesystem;

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

FuzzCampaignOptions campaign_options(const FuzzArgs& args) {
    FuzzCampaignOptions o;
    o.elf = args.elf;
    o.board = args.board;
    o.duration = args.duration;
    o.runs = args.runs;
    o.bound = args.bound;
    o.out = args.out;
    o.family = args.family;
    o.corpus = args.corpus;
    o.firmware = firmware_assignments(args.firmware);
    o.raw = args.raw;
    o.hang = args.hang;
    o.steady = args.steady;
    o.boot = args.boot;
    o.engine = args.engine;
    o.jobs = args.jobs;
    o.seed = args.seed;
    return o;
}

// --replay: exit code as `run --strict`'s: every finding the target would
// report fails it.
int replay_command(const FuzzArgs& args) {
    const BoardRunOptions o = fuzz_replay_run(campaign_options(args), args.replay);
    if (auto debug = debug_options(DebugArgs{args.gdb, args.break_at_finding, args.break_at, args.break_at_cycle})) {
        Debugger debugger(*debug);
        const auto run = run_board_debugged(o, debugger);
        for (const std::string& line : run->summary()) std::printf("%s\n", line.c_str());
        const int code = exit_code(debugged_verdict(debugger, run->verdict(true)));
        debugger.run_ended(code);
        return code;
    }
    BoardRun run(o);
    run.run();
    for (const std::string& line : run.summary()) std::printf("%s\n", line.c_str());
    return exit_code(run.verdict(true));
}

}  // namespace

int fuzz_command(const FuzzArgs& raw_args) {
    const FuzzArgs args = checked(raw_args);
    if (!args.replay.empty()) return replay_command(args);
    if (!args.gdb.empty() || args.break_at_finding || !args.break_at.empty() || !args.break_at_cycle.empty()) {
        throw BadInput("--gdb and the --break-at options need --replay FILE (a campaign runs without a debugger)");
    }
    return run_fuzz_campaign(campaign_options(args));
}

}  // namespace avrbench
