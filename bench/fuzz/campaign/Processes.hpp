// Child processes of a fuzz campaign: the engines, the target's replays and
// the recorded `avrbench run`s, each with its output in a log file.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace avrbench::fuzz_campaign {

// The folder of the running avrbench executable.
std::string self_dir();
// A helper installed beside avrbench (or in the build tree).
std::string find_helper(const std::string& name);
// A fuzz target, or the path in `override_variable` when set.
std::string find_target(const std::string& name, const char* override_variable);
// `program` on PATH; BadInput naming the Debian package otherwise.
std::string find_on_path(const std::string& program, const std::string& package);
// Starts argv with `env` added to the environment, stdout and stderr to `log`.
pid_t spawn_logged(const std::vector<std::string>& argv, const std::vector<std::string>& env, const std::string& log);
// Its exit status (128 + signal when killed); a stop request is passed on.
int wait_for(pid_t pid);
int run_logged(const std::vector<std::string>& argv, const std::vector<std::string>& env, const std::string& log);
// A file's whole text ("" when unreadable).
std::string slurp(const std::string& path);

}  // namespace avrbench::fuzz_campaign
