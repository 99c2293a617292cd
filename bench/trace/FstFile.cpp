#include "trace/FstFile.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "core/Errors.hpp"

extern char** environ;

namespace avrbench {

bool is_fst_path(const std::string& path) {
    if (path.size() < 4) return false;
    std::string ext = path.substr(path.size() - 4);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".fst";
}

std::string vcd2fst_program(const std::string& option) {
    const char* path = std::getenv("PATH");
    std::string dirs = path != nullptr ? path : "/usr/bin:/bin";
    std::size_t start = 0;
    while (start <= dirs.size()) {
        const std::size_t end = std::min(dirs.find(':', start), dirs.size());
        const std::string dir = dirs.substr(start, end - start);
        const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/vcd2fst";
        if (::access(candidate.c_str(), X_OK) == 0) return candidate;
        start = end + 1;
    }
    throw BadInput(option + ": writing FST needs vcd2fst (Debian's gtkwave package), which is not on PATH");
}

std::string vcd_for_fst(const std::string& fst_path) {
    // The process's id in the name: never a file of the user's, which
    // avrbench would not remove (docs/CLI.md, outputs).
    const std::filesystem::path p(fst_path);
    const std::string name = "." + p.filename().string() + "." + std::to_string(::getpid()) + ".vcd";
    const std::filesystem::path vcd = p.parent_path() / name;
    std::error_code ec;
    if (std::filesystem::symlink_status(vcd, ec).type() != std::filesystem::file_type::not_found) {
        throw BadInput("--vcd " + fst_path + ": " + vcd.string() + " exists; avrbench writes the VCD for the FST there");
    }
    return vcd.string();
}

void convert_vcd_to_fst(const std::string& vcd_path, const std::string& fst_path, const std::string& option) {
    const std::string program = vcd2fst_program(option);
    const std::filesystem::path target(fst_path);
    const std::string partial = (target.parent_path() / ("." + target.filename().string() + ".partial")).string();
    std::vector<std::string> args{program, vcd_path, partial};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    // vcd2fst reports its progress on stdout and stderr: not the run's output.
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    pid_t pid = 0;
    const int spawned = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    int status = 0;
    const bool ran = spawned == 0 && ::waitpid(pid, &status, 0) == pid;
    std::error_code ec;
    std::filesystem::remove(vcd_path, ec);
    if (!ran || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::filesystem::remove(partial, ec);
        throw BadInput(option + ": " + program + " could not convert the run's VCD into " + fst_path);
    }
    std::filesystem::rename(partial, target, ec);
    if (ec) {
        std::filesystem::remove(partial, ec);
        throw BadInput(option + ": cannot write " + fst_path + ": " + ec.message());
    }
}

}  // namespace avrbench
