#include "debug/DebugRun.hpp"

#include "debug/RunViews.hpp"

namespace avrbench {

std::unique_ptr<BoardRun> run_board_debugged(const BoardRunOptions& options, Debugger& debugger) {
    std::unique_ptr<BoardRun> run;
    bool listening = false;
    // Each replay (reverse execution) is a new run of the same options. The
    // ports open once the first run's board is known good and names the
    // MCUs asked for: nothing is announced for a run that cannot start.
    debugger.run_replays([&] {
        run.reset();
        run = std::make_unique<BoardRun>(options);
        if (!listening) {
            debugger.check_targets(run->bench().board().mcus());
            debugger.listen();
            listening = true;
        }
        debugger.attach(run->bench().board().mcus(), board_debug_view(run->bench(), run->host(), !options.pty.has_value()));
        run->run();
    });
    debugger.detach();  // the front end tells the debugger the exit code (Debugger::run_ended)
    return run;
}

std::unique_ptr<McuRun> run_mcu_debugged(const McuRunOptions& options, Debugger& debugger) {
    std::unique_ptr<McuRun> run;
    bool listening = false;
    debugger.run_replays([&] {
        run.reset();
        run = std::make_unique<McuRun>(options);
        if (!listening) {
            debugger.check_targets({&run->mcu()});
            debugger.listen();
            listening = true;
        }
        debugger.attach({&run->mcu()}, mcu_debug_view(*run));
        run->run();
    });
    debugger.detach();  // the front end tells the debugger the exit code (Debugger::run_ended)
    return run;
}

RunVerdict debugged_verdict(const Debugger& debugger, RunVerdict verdict) {
    if (debugger.killed()) return {RunVerdict::Outcome::Interrupted, "the debugger killed the program"};
    return verdict;
}

}  // namespace avrbench
