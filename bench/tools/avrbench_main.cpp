// The avrbench command line: parses, dispatches to a subcommand, and turns
// errors into one line and an exit code (docs/CLI.md). Thin by design: every
// subcommand runs through the library (run/BoardRun, verify/Scenario, ...).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <memory>
#include <vector>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "core/UserStop.hpp"
#include "tools/Commands.hpp"
#include "tools/UsageHint.hpp"
#include "tools/FuzzCommand.hpp"

namespace avrbench {

int exit_code(const RunVerdict& verdict) {
    if (!verdict.message.empty()) std::fprintf(stderr, "avrbench: %s\n", verdict.message.c_str());
    switch (verdict.outcome) {
        case RunVerdict::Outcome::Ok: return kExitOk;
        case RunVerdict::Outcome::Finding: return kExitFinding;
        case RunVerdict::Outcome::Timeout: return kExitTimeout;
        case RunVerdict::Outcome::Interrupted: return kExitInterrupted;
    }
    return kExitInternal;
}

Command add_fuzz_command(CLI::App& app) {
    auto args = std::make_shared<FuzzArgs>();
    FuzzArgs& fuzz = *args;
    CLI::App* fuzz_cmd = app.add_subcommand("fuzz", "coverage-guided G-code fuzzing of a firmware on a board (libFuzzer or AFL++; docs/FUZZING.md)");
    fuzz_cmd->add_option("--elf", fuzz.elf, "the firmware")->required();
    fuzz_cmd->add_option("--board", fuzz.board, "board file or standard board name; --elf runs on its serial port's MCU")->required();
    fuzz_cmd->add_option("--for", fuzz.duration, "wall-clock time of the campaign (default 60s; with --runs its upper bound)");
    fuzz_cmd->add_option("--runs", fuzz.runs_text,
                         "executions of the campaign: with one job and a --seed, the same inputs on any machine "
                         "(libFuzzer -runs, AFL++ -E)");
    fuzz_cmd->add_option("--bound", fuzz.bound, "simulated time one input may take (default 5s; above the port's line timeout)");
    fuzz_cmd->add_option("--out", fuzz.out, "corpus, reproducers, runs and the libFuzzer log (default fuzz-out)");
    fuzz_cmd->add_option("--family", fuzz.family, "the host's firmware family: grbl, marlin, prusa, teacup, repetier, sprinter, generic (default: the board's)");
    fuzz_cmd->add_flag("--hang", fuzz.hang, "a line still unanswered when --bound ends is a finding, keep-alives or not");
    fuzz_cmd->add_flag("--raw", fuzz.raw, "send the input's bytes to the port as they are (binary protocols such as seed 002's records)");
    fuzz_cmd->add_option("--boot", fuzz.boot, "with --raw, or a generic firmware that prints no banner: simulated time the firmware boots before the first input (default 0.2s; a generic one's first output line ends it sooner)");
    fuzz_cmd->add_option("--steady", fuzz.steady,
                         "AVR instructions an input may only repeat itself before it ends: stepping, no new coverage, "
                         "no part able to find more at that pace before --bound (default 100000; 0: every input to --bound)")
        ->check(CLI::Range(0ull, 1000000000000ull));
    fuzz_cmd->add_option("--firmware", fuzz.firmware, "MCU=ELF for a multi-MCU board's other MCUs (repeatable; as run's)");
    fuzz_cmd->add_option("--corpus", fuzz.corpus, "a directory of seed inputs (your jobs' lines) added to the family's seed lines");
    fuzz_cmd->add_option("--engine", fuzz.engine, "libfuzzer (default) or afl (Debian's afl++: one main and --jobs - 1 secondary instances)")
        ->check(CLI::IsMember({"libfuzzer", "afl"}));
    fuzz_cmd->add_option("--jobs", fuzz.jobs, "parallel jobs: libFuzzer's fork jobs or AFL++ instances (default 1)");
    fuzz_cmd->add_option("--seed", fuzz.seed, "the engine's random seed (default 1)");
    fuzz_cmd->add_option("--replay", fuzz.replay,
                         "run this one input (a reproducer) as the fuzz target sends it, no campaign; exit 1 when it finds something");
    fuzz_cmd->add_option("--gdb", fuzz.gdb, "--replay under avr-gdb: [MCU=]PORT (as run --gdb; docs/DEBUGGING.md)");
    fuzz_cmd->add_flag("--break-at-finding", fuzz.break_at_finding, "--replay --gdb: stop at each finding");
    fuzz_cmd->add_option("--break-at", fuzz.break_at, "--replay --gdb: stop at the first instruction at or after this time");
    fuzz_cmd->add_option("--break-at-cycle", fuzz.break_at_cycle, "--replay --gdb: stop at this cycle");

    return {fuzz_cmd, [args] { return fuzz_command(*args); }};
}

namespace {

// `--vcd ''` is a mistake, not "no VCD": an option that takes a value and
// was given an empty one is bad usage, for every option of every command.
void reject_empty_values(const CLI::App& app) {
    for (const CLI::App* command : app.get_subcommands()) {
        for (const CLI::Option* option : command->get_options()) {
            if (option->count() == 0 || option->get_type_size() == 0) continue;  // not given, or a flag
            for (const std::string& value : option->results()) {
                if (value.empty()) throw BadInput(option->get_name() + ": an empty value");
            }
        }
        reject_empty_values(*command);
    }
}

}  // namespace
}  // namespace avrbench

int main(int argc, char** argv) {
    using namespace avrbench;
    CLI::App app{"avrbench: a cycle-level test bench for AVR firmware (simavr inside)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("avrbench ") + AVRBENCH_VERSION);
    std::vector<Command> commands = {add_run_command(app)};
    for (Command& c : add_check_commands(app)) commands.push_back(std::move(c));
    for (Command& c : add_info_commands(app)) commands.push_back(std::move(c));
    commands.push_back(add_fuzz_command(app));
    commands.push_back(add_board_command(app));

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "avrbench: usage error: %s%s (see avrbench --help)\n", escaped(e.what()).c_str(),
                     escaped(usage_hint(app, argc, argv)).c_str());
        return kExitBadInput;
    }
    install_user_stop_handlers();
    int code = 0;
    try {
        reject_empty_values(app);
        for (const Command& c : commands) {
            if (c.command->parsed()) code = c.run();
        }
    } catch (const BadInput& e) {
        // Escaped: a message that quotes a user's string stays one line and
        // never drives the terminal (core/InputFile.hpp).
        std::fflush(stdout);
        std::fprintf(stderr, "avrbench: error: %s\n", escaped(e.what()).c_str());
        code = kExitBadInput;
    } catch (const std::exception& e) {
        std::fflush(stdout);
        std::fprintf(stderr, "avrbench: internal error: %s\n", escaped(e.what()).c_str());
        code = kExitInternal;
    }
    // A summary that could not be written is a failed run (a full disk, a closed pipe).
    if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
        std::fprintf(stderr, "avrbench: error: cannot write to standard output\n");
        return kExitBadInput;
    }
    return code;
}
