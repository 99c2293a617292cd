// `avrbench check` and `avrbench golden update`: scenario files through
// verify/ScenarioRun, JUnit for CI.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "core/OutputFile.hpp"
#include "core/UserStop.hpp"
#include "tools/Commands.hpp"
#include "trace/Junit.hpp"
#include "debug/Debugger.hpp"
#include "debug/RunViews.hpp"
#include "run/Bench.hpp"
#include "verify/Scenario.hpp"

namespace avrbench {
namespace {

// build/avrbench -> build/firmware, where the build puts our firmware ELFs.
std::string default_firmware_dir() {
    if (const char* env = std::getenv("AVRBENCH_FIRMWARE_DIR")) return env;
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::string("build/firmware") : (exe.parent_path() / "firmware").string();
}

struct CheckArgs {
    bool force = false;
    std::vector<std::string> scenarios;
    std::string junit;
    std::string report_dir;
    std::string vcd_dir;
    std::string firmware_dir;
    DebugArgs debug;                 // --gdb, --break-at...: one scenario under avr-gdb
    bool break_at_divergence = false;
};

// `check --gdb`: one scenario run with avr-gdb attached (docs/DEBUGGING.md);
// with --break-at-divergence it first runs undebugged to find where its
// timeline leaves the golden, then stops there.
int check_debugged(const CheckArgs& args, DebugOptions debug, const std::string& firmware_dir) {
    if (args.scenarios.size() != 1) throw BadInput("--gdb: give one scenario (it runs under the debugger)");
    const ScenarioSpec spec = load_scenario(args.scenarios.front(), firmware_dir);
    ScenarioRunOptions options;
    options.report_dir = args.report_dir;
    options.vcd_dir = args.vcd_dir;
    if (args.break_at_divergence) {
        const ScenarioResult first = run_scenario(spec, ScenarioRunOptions{});
        const ChannelResult* divergence = first.comparison ? first.comparison->first_divergence() : nullptr;
        if (divergence == nullptr) {
            std::fprintf(stderr, "avrbench: %s: the timeline does not leave its golden; no --break-at-divergence stop\n",
                         spec.name.c_str());
        } else {
            debug.break_at_ps = static_cast<Picoseconds>(std::ceil(static_cast<long double>(divergence->divergence_cycle) *
                                                                   static_cast<long double>(kPsPerSecond) /
                                                                   divergence->clock_hz));
            std::fprintf(stderr, "avrbench: %s: %s leaves the golden at %.9f s: stopping there\n", spec.name.c_str(),
                         divergence->signal.c_str(), divergence->seconds());
        }
    }
    Debugger debugger(debug);
    debugger.listen();
    options.prepared = [&debugger](Bench& bench) { debugger.attach(bench.board().mcus(), board_debug_view(bench, nullptr, true)); };
    ScenarioResult result;
    debugger.run_replays([&] { result = run_scenario(spec, options); });
    debugger.detach();
    std::fputs(result.text().c_str(), stdout);
    if (debugger.killed()) {
        std::fprintf(stderr, "avrbench: the debugger killed the program\n");
        debugger.run_ended(kExitInterrupted);
        return kExitInterrupted;
    }
    const int code = result.passed ? kExitOk : kExitFinding;
    debugger.run_ended(code);
    return code;
}

// GoogleTest's sharding variables, so a CI matrix splits scenario lists the
// way it splits gtest binaries.
std::vector<std::string> shard(const std::vector<std::string>& all) {
    const char* total_env = std::getenv("GTEST_TOTAL_SHARDS");
    const char* index_env = std::getenv("GTEST_SHARD_INDEX");
    if (total_env == nullptr || index_env == nullptr) return all;
    const long total = std::strtol(total_env, nullptr, 10), index = std::strtol(index_env, nullptr, 10);
    if (total <= 0 || index < 0 || index >= total) throw BadInput("GTEST_TOTAL_SHARDS/GTEST_SHARD_INDEX are inconsistent");
    std::vector<std::string> mine;
    for (std::size_t i = 0; i < all.size(); ++i) {
        if (static_cast<long>(i % static_cast<std::size_t>(total)) == index) mine.push_back(all[i]);
    }
    return mine;
}

JunitCase junit_case(const ScenarioResult& r) {
    JunitCase c;
    c.name = r.name;
    c.time_s = r.wall_s;
    c.outcome = r.error ? JunitCase::Outcome::Error : r.passed ? JunitCase::Outcome::Passed : JunitCase::Outcome::Failed;
    c.message = r.failures.empty() ? "" : r.failures.front();
    c.text = r.text();
    return c;
}

// Runs every scenario it is given: one that cannot load or run is an error
// result (its file:line message in the output and the JUnit file), never the
// end of the batch. Exit: 2 if any scenario had an error, else 1 if any
// failed (or, updating goldens, was refused), else 0.
int check_command(const CheckArgs& args, bool update_golden) {
    const std::string firmware_dir = args.firmware_dir.empty() ? default_firmware_dir() : args.firmware_dir;
    if (args.break_at_divergence && args.debug.gdb.empty()) throw BadInput("--break-at-divergence needs --gdb [MCU=]PORT");
    if (auto debug = debug_options(args.debug)) return check_debugged(args, *debug, firmware_dir);
    // The report folder first: it is ours to create, and --junit may point into it.
    if (!args.report_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(args.report_dir, ec);
        if (ec || !std::filesystem::is_directory(args.report_dir, ec)) {
            throw BadInput("--report-dir: " + args.report_dir + ": cannot create the folder");
        }
    }
    if (!args.vcd_dir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(args.vcd_dir, ec);
        if (ec || !std::filesystem::is_directory(args.vcd_dir, ec)) {
            throw BadInput("--vcd-dir: " + args.vcd_dir + ": cannot create the folder");
        }
    }
    if (!args.junit.empty()) check_output_path(args.junit, "--junit");
    ScenarioRunOptions options;
    options.report_dir = args.report_dir;
    options.vcd_dir = args.vcd_dir;
    options.update_golden = update_golden;
    options.force = args.force;
    std::vector<ScenarioResult> results;
    for (const auto& path : update_golden ? args.scenarios : shard(args.scenarios)) {
        if (user_stop_requested()) break;
        try {
            const ScenarioSpec spec = load_scenario(path, firmware_dir);
            results.push_back(run_scenario(spec, options));
            if (update_golden && results.back().passed && !spec.golden_path.empty()) {
                std::printf("%s: golden timeline written to %s (%.3f s simulated)\n", spec.name.c_str(),
                            spec.golden_path.c_str(), results.back().simulated_s);
                continue;
            }
            if (update_golden && results.back().passed) {
                std::printf("%s: no golden timeline (the scenario names none)\n", spec.name.c_str());
                continue;
            }
        } catch (const BadInput& e) {
            results.push_back(error_result(path, escaped(e.what())));
            std::fflush(stdout);
            std::fprintf(stderr, "avrbench: error: %s\n", escaped(e.what()).c_str());
        }
        std::fputs(results.back().text().c_str(), stdout);
    }
    if (!args.junit.empty()) {
        std::vector<JunitCase> cases;
        for (const auto& r : results) cases.push_back(junit_case(r));
        write_output_file(args.junit, junit_xml(cases, "avrbench"), "--junit");
    }
    std::size_t failed = 0, errors = 0;
    for (const auto& r : results) {
        errors += r.error ? 1 : 0;
        failed += !r.error && !r.passed ? 1 : 0;
    }
    if (errors > 0) std::printf("%zu scenario(s) could not be loaded or run (ERROR above)\n", errors);
    if (user_stop_requested()) {
        std::printf("%zu passed, %zu failed\n", results.size() - failed - errors, failed + errors);
        std::fprintf(stderr, "avrbench: interrupted after %zu scenario(s); their results are written\n", results.size());
        return kExitInterrupted;
    }
    std::printf("%zu passed, %zu failed\n", results.size() - failed - errors, failed + errors);
    return errors > 0 ? kExitBadInput : failed > 0 ? kExitFinding : kExitOk;
}

}  // namespace

std::vector<Command> add_check_commands(CLI::App& app) {
    auto check_args = std::make_shared<CheckArgs>();
    auto golden_args = std::make_shared<CheckArgs>();
    CheckArgs& check = *check_args;
    CheckArgs& golden = *golden_args;
    CLI::App* check_cmd = app.add_subcommand("check", "run scenario files: stimulus, expectations, golden comparison");
    check_cmd->add_option("scenarios", check.scenarios, "scenario files (tests/scenarios/*.yaml)")->required();
    check_cmd->add_option("--junit", check.junit, "write JUnit XML for CI");
    check_cmd->add_option("--report-dir", check.report_dir, "write an HTML report per scenario here");
    check_cmd->add_option("--vcd-dir", check.vcd_dir,
                          "write each scenario's waveforms here: <name>.vcd (sigrok-readable) and <name>.gtkw");
    check_cmd->add_option("--firmware-dir", check.firmware_dir, "where bare firmware names resolve (default: beside avrbench)");
    check_cmd->add_option("--gdb", check.debug.gdb,
                          "[MCU=]PORT: run the one scenario given with avr-gdb attached (as run --gdb; docs/DEBUGGING.md)");
    check_cmd->add_flag("--break-at-finding", check.debug.break_at_finding, "--gdb: stop at each finding");
    check_cmd->add_option("--break-at", check.debug.break_at, "--gdb: stop at the first instruction at or after this time");
    check_cmd->add_option("--break-at-cycle", check.debug.break_at_cycle, "--gdb: stop at the first instruction at or after this cycle");
    check_cmd->add_flag("--break-at-divergence", check.break_at_divergence,
                        "--gdb: run the scenario once to find where it leaves its golden timeline, then debug it stopping there");
    CLI::App* golden_cmd = app.add_subcommand("golden", "manage golden timelines");
    golden_cmd->require_subcommand(1);
    CLI::App* update_cmd = golden_cmd->add_subcommand("update", "rerun scenarios and rewrite their golden timelines (never done implicitly)");
    update_cmd->add_option("scenarios", golden.scenarios, "scenario files")->required();
    update_cmd->add_option("--firmware-dir", golden.firmware_dir, "where bare firmware names resolve");
    update_cmd->add_flag("--force", golden.force, "write the golden even when the run fails its steps or expectations");

    return {{check_cmd, [check_args] { return check_command(*check_args, false); }},
            {update_cmd, [golden_args] { return check_command(*golden_args, true); }}};
}

}  // namespace avrbench
