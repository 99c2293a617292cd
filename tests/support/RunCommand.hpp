// Runs a command line through the shell and captures its exit code and output.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace avrbench::test {

struct CommandResult {
    int exit_code = -1;
    std::string out;
    std::string err;
};

inline std::string slurp(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// The scratch directories the running test made; tests/support/
// ScratchCleanup.cpp removes them when the test passes (a failed test's stay
// for a look, as do all with AVRBENCH_KEEP_SCRATCH=1).
inline std::vector<std::filesystem::path>& scratch_dirs_of_this_test() {
    static std::vector<std::filesystem::path> dirs;
    return dirs;
}

// A fresh scratch directory per test, in the system's temp space.
inline std::filesystem::path scratch_dir(const std::string& name) {
    auto dir = std::filesystem::temp_directory_path() / ("avrbench-test-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    scratch_dirs_of_this_test().push_back(dir);
    return dir;
}

inline std::string escape_single_quotes(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '\'') out += "'\\''";
        else out += c;
    }
    return out;
}

// Exit code 124: the command ran past `wall_limit_s` of wall time and was
// killed (coreutils timeout): a hang fails the test instead of CI.
constexpr int kTimedOut = 124;

inline CommandResult run_command(const std::string& command, const std::filesystem::path& dir, int wall_limit_s = 120) {
    const auto out = dir / "stdout.txt";
    const auto err = dir / "stderr.txt";
    const std::string full = "timeout -k 5 " + std::to_string(wall_limit_s) + " sh -c '" +
                             escape_single_quotes(command) + "' >" + out.string() + " 2>" + err.string() + " </dev/null";
    const int status = std::system(full.c_str());
    CommandResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

inline std::string quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace avrbench::test
