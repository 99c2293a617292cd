// qemu-system-avr on the same ELF as the bench, for `avrbench_perf --mips`:
// QEMU's TCG (a JIT, not cycle-exact) runs the program until the PC leaves
// its work loop for the end label; QEMU's own CPU time from its start to
// then is the measure: its threads' time on a CPU in nanoseconds
// (/proc/<pid>/task/*/schedstat, proc(5)), or where the kernel does not
// keep that, utime + stime from /proc/<pid>/stat in clock ticks (10 ms).
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace avrbench_perf {
namespace {

pid_t spawn(const std::vector<std::string>& argv, const std::string& out_path) {
    const pid_t pid = fork();
    if (pid == 0) {
        const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int null_in = open("/dev/null", O_RDONLY);
        dup2(null_in, STDIN_FILENO);
        dup2(out, STDOUT_FILENO);
        dup2(out, STDERR_FILENO);
        std::vector<char*> args;
        for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        execvp(args[0], args.data());
        _exit(127);
    }
    return pid;
}

std::string slurp(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

// "qemu-system-avr <version>" from `qemu-system-avr --version`, or "" when it does not run.
std::string qemu_version() {
    const auto out = (std::filesystem::temp_directory_path() / ("avrbench_perf_qemu_version_" + std::to_string(getpid()))).string();
    const pid_t pid = spawn({"qemu-system-avr", "--version"}, out);
    int status = 0;
    waitpid(pid, &status, 0);
    std::string text = slurp(out);
    std::filesystem::remove(out);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "";
    // "QEMU emulator version 7.2.22 (Debian ...)" -> "qemu-system-avr 7.2.22"
    std::istringstream words(text.substr(0, text.find('\n')));
    std::string word, version;
    while (words >> word) {
        if (word == "version") words >> version;
    }
    return "qemu-system-avr " + (version.empty() ? std::string("?") : version);
}

// QEMU's CPU seconds (utime + stime of its process) from its start to the
// PC leaving [from_addr, to_addr) once seen inside (flash byte addresses:
// the program's main and its end label) - or, with `stop_on_entry`, to the
// PC first inside it (a program whose work runs in other functions: the
// range is its end loop) - on an Arduino UNO machine, polled
// through QEMU's monitor every 5 ms; -1 with `why` set when it cannot.
// (A debugger's breakpoints would mark the two places exactly, but with
// QEMU's gdb stub attached its TCG ran the same loop 4x slower: measured
// 3.2 s against 0.8 s on busy_poll_passes.) With the nanosecond clock the
// end is placed between two polls, within 2.5 ms of QEMU's time (2.5 % of
// the workload suite's shortest kernel, 0.1 s); with clock ticks a poll and
// a tick (15 ms) can be added.
double qemu_cpu_seconds(const std::string& elf, std::uint32_t from_addr, std::uint32_t to_addr, std::string& why,
                        bool stop_on_entry) {
    int to_qemu[2], from_qemu[2];
    if (pipe(to_qemu) != 0 || pipe(from_qemu) != 0) {
        why = "no pipes";
        return -1;
    }
    const pid_t qemu = fork();
    if (qemu == 0) {
        dup2(to_qemu[0], STDIN_FILENO);
        dup2(from_qemu[1], STDOUT_FILENO);
        dup2(from_qemu[1], STDERR_FILENO);
        close(to_qemu[1]);
        close(from_qemu[0]);
        // Paused (-S) until `cont`, so its time is counted from the start of the program.
        execlp("qemu-system-avr", "qemu-system-avr", "-M", "uno", "-bios", elf.c_str(), "-display", "none", "-serial",
               "none", "-monitor", "stdio", "-S", static_cast<char*>(nullptr));
        _exit(127);
    }
    close(to_qemu[0]);
    close(from_qemu[1]);
    fcntl(from_qemu[0], F_SETFL, O_NONBLOCK);
    const std::string stat = "/proc/" + std::to_string(qemu) + "/stat";
    // Nanoseconds on a CPU, all of QEMU's threads (its TCG thread and its
    // main loop, which answers the monitor), or -1.
    const std::string tasks = "/proc/" + std::to_string(qemu) + "/task";
    const auto schedstat_ns = [&tasks]() -> long long {
        long long sum = 0;
        std::error_code error;
        int threads = 0;
        for (const auto& task : std::filesystem::directory_iterator(tasks, error)) {
            const std::string text = slurp(task.path().string() + "/schedstat");
            if (text.empty()) continue;  // a thread that just ended
            sum += std::atoll(text.c_str());
            ++threads;
        }
        return error || threads == 0 ? -1 : sum;
    };
    const auto ticks = [&stat]() -> long long {
        const std::string text = slurp(stat);
        // Fields 14 and 15: utime and stime in clock ticks, after the command
        // name in parentheses (which may hold spaces).
        const auto close_paren = text.rfind(')');
        if (close_paren == std::string::npos) return -1;
        std::istringstream fields(text.substr(close_paren + 2));
        std::string f;
        long long sum = 0;
        for (int field = 3; fields >> f && field <= 15; ++field) {
            if (field >= 14) sum += std::stoll(f);
        }
        return sum;
    };
    const auto say = [&](const char* command) { return write(to_qemu[1], command, std::strlen(command)) > 0; };
    std::string out;
    const auto read_some = [&] {
        char buf[4096];
        for (ssize_t n; (n = read(from_qemu[0], buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
    };
    // The PC in the latest `info registers` answer ("PC:    00009c"), or -1.
    const auto last_pc = [&out]() -> long {
        const auto at = out.rfind("PC:");
        if (at == std::string::npos) return -1;
        return std::strtol(out.c_str() + at + 3, nullptr, 16);
    };
    double seconds = -1;
    bool started = false;  // the PC seen inside the work (the start-up code runs before it)
    long last = -1;
    int same = 0;  // polls in a row at the same PC
    // QEMU's CPU time in seconds (see the top of the file), or < 0.
    const bool in_ns = schedstat_ns() >= 0;
    const auto cpu_seconds = [&]() -> double {
        if (in_ns) return static_cast<double>(schedstat_ns()) * 1e-9;
        const long long t = ticks();
        return t < 0 ? -1.0 : static_cast<double>(t) / static_cast<double>(sysconf(_SC_CLK_TCK));
    };
    const double start = cpu_seconds();
    // The end was passed between the poll before and this one: the middle
    // of the two is the estimate (off by half a poll, 2.5 ms, at most).
    double previous = start;
    if (start >= 0 && say("cont\n")) {
        for (int poll = 0; poll < 60 * 200; ++poll) {  // at most a minute of wall time
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
            const double now = cpu_seconds();
            out.clear();
            if (!say("info registers\n")) break;
            for (int wait = 0; wait < 200 && last_pc() < 0; ++wait) {
                std::this_thread::sleep_for(std::chrono::microseconds(250));
                read_some();
            }
            const long pc = last_pc();
            if (pc < 0) break;
            // qemu-system-avr 7.2 can stop advancing (a PC the same for a
            // minute, seen in the workload suite): 10 s at one PC ends the wait.
            same = pc == last ? same + 1 : 0;
            last = pc;
            if (same >= 2000 && !(pc >= static_cast<long>(from_addr) && pc < static_cast<long>(to_addr))) {
                char text[96];
                std::snprintf(text, sizeof text, "qemu-system-avr's PC stayed at 0x%lx for 10 s", pc);
                why = text;
                break;
            }
            const bool inside = pc >= static_cast<long>(from_addr) && pc < static_cast<long>(to_addr);
            if (inside) started = true;
            if (stop_on_entry ? inside : started && !inside) {
                seconds = (in_ns ? (previous + now) / 2 : now) - start;
                break;
            }
            previous = now;
        }
    }
    if (seconds < 0 && why.empty()) why = stop_on_entry ? "qemu-system-avr did not reach the end label" : "qemu-system-avr did not run from main past busy_poll_done's loop";
    kill(qemu, SIGKILL);
    int status = 0;
    waitpid(qemu, &status, 0);
    close(to_qemu[1]);
    close(from_qemu[0]);
    return seconds;
}

}  // namespace avrbench_perf
