#include "fuzz/campaign/Processes.hpp"

#include <algorithm>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/Errors.hpp"
#include "core/UserStop.hpp"

extern char** environ;

namespace avrbench::fuzz_campaign {

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

}  // namespace avrbench::fuzz_campaign
