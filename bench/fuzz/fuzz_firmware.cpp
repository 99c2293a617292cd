// libFuzzer front end of the firmware fuzz target (FirmwareTarget.hpp says
// what it runs and which findings it reports): G-code (or any bytes) into a
// board's serial port, coverage taken from the firmware's own program
// counter through libFuzzer's extra counters.
//
// Besides FirmwareTarget's variables:
//   AVRBENCH_FUZZ_SEEN   a file of the finding kinds already reported in the
//                        campaign (FuzzFindings.hpp): an input whose finding
//                        is of a kind listed there is not a crash, so a job
//                        is not stopped and restarted for the same bug again
//
//   AVRBENCH_FUZZ_CRASH_DIR  set: a finding does not stop libFuzzer. The
//                        input is written to <dir>/crash-<hash of its bytes>
//                        (where libFuzzer would put it), its one line printed,
//                        and the campaign goes on in this one process: a
//                        campaign that `avrbench fuzz` runs in-process, whose
//                        course depends on -seed and -runs only, not on the
//                        machine's speed. Unset: a finding aborts, and
//                        libFuzzer (in fork mode, -ignore_crashes) keeps the
//                        input as crash-*.
//
// Per input the target runs from the booted board's snapshot in this
// process and puts the board back (FirmwareTarget.hpp), its PC edges going
// straight into libFuzzer's extra counters; with AVRBENCH_FUZZ_FORK=1 (and in
// sanitizer builds) it forks per input instead.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "FuzzFindings.hpp"
#include "FuzzMutator.hpp"
#include "FirmwareTarget.hpp"

namespace {

constexpr std::uint32_t kMapSize = 1u << 16;

struct Shared {
    std::uint8_t edges[kMapSize];
    avrbench::fuzz::InputOutcome outcome;
};

// libFuzzer reads every byte of this section as a coverage counter.
__attribute__((section("__libfuzzer_extra_counters"), used)) std::uint8_t g_counters[kMapSize];

Shared* g_shared = nullptr;

// Inputs run, and those that ended repeating themselves before their bound
// (FirmwareTarget.hpp, AVRBENCH_FUZZ_STEADY): said once at exit, so a
// campaign tells what it did not run to the end.
unsigned long long g_inputs = 0;
unsigned long long g_ended_steady = 0;

void say_steady_count() {
    if (g_inputs == 0) return;
    std::fprintf(stderr, "avrbench fuzz: %llu of %llu inputs ended repeating themselves before their bound\n",
                 g_ended_steady, g_inputs);
}

// crash-<FNV-1a of the bytes, 16 hex digits>: one file per distinct input.
void save_crash(const char* dir, const std::uint8_t* data, std::size_t size) {
    std::uint64_t hash = 0xcbf29ce484222325ull;
    for (std::size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * 0x100000001b3ull;
    char name[32];
    std::snprintf(name, sizeof name, "/crash-%016llx", static_cast<unsigned long long>(hash));
    std::ofstream out(std::string(dir) + name, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) std::fprintf(stderr, "fuzz_firmware: cannot write %s%s\n", dir, name);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
    const char* who = "fuzz_firmware";
    const char* executable = argc != nullptr && *argc > 0 ? (*argv)[0] : nullptr;
    avrbench::fuzz::boot_target(avrbench::fuzz::config_from_environment(who, executable), who);
    std::atexit(say_steady_count);
    if (avrbench::fuzz::target_restores()) return 0;
    void* shared = ::mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (shared == MAP_FAILED) {
        std::perror("fuzz_firmware: mmap");
        std::exit(2);
    }
    g_shared = static_cast<Shared*>(shared);
    return 0;
}

namespace {

// The fork path (AVRBENCH_FUZZ_FORK=1, sanitizer builds): the child runs the
// input and leaves the edge map and the outcome in memory shared with this
// process, which copies the map into libFuzzer's extra counters.
avrbench::fuzz::InputOutcome run_forked(const std::uint8_t* data, std::size_t size) {
    std::memset(g_shared->edges, 0, kMapSize);
    g_shared->outcome = avrbench::fuzz::InputOutcome{};
    const pid_t child = ::fork();
    if (child < 0) {
        std::perror("fuzz_firmware: fork");
        std::abort();
    }
    if (child == 0) {
        avrbench::fuzz::run_input(data, size, g_shared->edges, kMapSize - 1, g_shared->outcome);
        ::_exit(0);
    }
    int status = 0;
    while (::waitpid(child, &status, 0) < 0) {
    }
    std::memcpy(g_counters, g_shared->edges, kMapSize);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::fprintf(stderr, "fuzz_firmware: the bench itself died on this input (status 0x%x): a bug of the bench\n", status);
        std::abort();
    }
    return g_shared->outcome;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    avrbench::fuzz::InputOutcome outcome;
    if (avrbench::fuzz::target_restores()) {
        std::memset(g_counters, 0, kMapSize);
        avrbench::fuzz::run_input_and_restore(data, size, g_counters, kMapSize - 1, outcome);
    } else {
        outcome = run_forked(data, size);
    }
    ++g_inputs;
    if (outcome.ended_steady) ++g_ended_steady;
    if (outcome.finding) {
        char line[sizeof outcome.detail + 96];
        std::snprintf(line, sizeof line, "avrbench fuzz: FINDING after %llu AVR instructions: %s",
                      static_cast<unsigned long long>(outcome.steps), outcome.detail);
        if (const char* seen = std::getenv("AVRBENCH_FUZZ_SEEN"); seen != nullptr && *seen != '\0') {
            // Each hit appends its root cause to <seen>.hits (the campaign
            // counts the inputs per cause); <seen> lists each cause once.
            const std::string cause = avrbench::finding_root_cause(line);
            const std::string entry = cause + "\n";
            const auto append = [&entry](const std::string& path) {
                // One short append (O_APPEND): jobs running side by side do not mix lines.
                const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
                if (fd < 0) return;
                (void)!::write(fd, entry.data(), entry.size());
                ::close(fd);
            };
            append(std::string(seen) + ".hits");
            std::ifstream in(seen);
            for (std::string known; std::getline(in, known);) {
                // Reported already: keep fuzzing, but keep the input out of the
                // corpus (-1), or inputs that crash at once would crowd it.
                if (known == cause) return -1;
            }
            append(seen);
        }
        std::fprintf(stderr, "%s\n", line);
        if (const char* dir = std::getenv("AVRBENCH_FUZZ_CRASH_DIR"); dir != nullptr && *dir != '\0') {
            save_crash(dir, data, size);
            return -1;
        }
        std::abort();
    }
    return 0;
}

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
    if (avrbench::fuzz::target_is_raw()) return LLVMFuzzerMutate(data, size, max_size);  // a binary protocol: bytes, not G-code
    return avrbench::fuzz::mutate_gcode(data, size, max_size, seed);
}
