// AFL++ front end of the firmware fuzz target (FirmwareTarget.hpp says what
// it runs and which findings it reports).
//
//   afl-fuzz -i seeds -o out -t 20000 -- avrbench-fuzz-firmware-afl @@
//   (or without @@: the input on standard input)
//
// The binary carries no compiler instrumentation: coverage is the firmware's,
// AVR program-counter edges counted straight into AFL's shared map (the
// System V segment named by __AFL_SHM_ID, 64 KiB). It boots the firmware
// once and then serves AFL's fork-server protocol itself on descriptors
// 198/199 (AFL++'s docs, "forkserver"): a 4-byte hello, then per input a
// 4-byte request, fork, the child's pid, its wait status (the hello
// carries the map size, below). The child is persistent (AFL++'s
// "persistent mode", announced by the signature below): it runs input after
// input from the booted board's snapshot (FirmwareTarget.hpp), stopping
// itself (SIGSTOP) after each, and the server resumes it (SIGCONT) for the
// next request instead of forking; after kInputsPerChild inputs the child
// exits and the next request forks a fresh one. So every execution starts
// from the booted firmware, as with libFuzzer. With AVRBENCH_FUZZ_FORK=1
// (and in sanitizer builds) each input gets a forked child of its own. A
// finding prints its one line to stderr and aborts, which AFL files under
// crashes/ (and the next input gets a fresh child).
//
// Started outside AFL (no fork server on 198), it runs the one input once:
// `avrbench-fuzz-firmware-afl crash-file` replays a reproducer (exit 0: no
// finding; a finding aborts).
#include <signal.h>
#include <sys/shm.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "FirmwareTarget.hpp"

namespace {

constexpr int kControlFd = 198;  // AFL's FORKSRV_FD; status goes to FORKSRV_FD + 1
constexpr int kStatusFd = kControlFd + 1;
constexpr std::uint32_t kMapSize = 1u << 16;  // AFL's default MAP_SIZE
constexpr const char* kWho = "fuzz_firmware_afl";
// A bound on what one child may leak into the process's heap over its life.
constexpr int kInputsPerChild = 10000;

// afl-fuzz looks for this string in the binary to run it in persistent mode.
__attribute__((used)) volatile const char kAflPersistentSignature[] = "##SIG_AFL_PERSISTENT##";

std::vector<std::uint8_t> read_input(const char* path) {
    if (path != nullptr) {
        std::ifstream in(path, std::ios::binary);
        if (!in) {
            std::fprintf(stderr, "%s: cannot read %s\n", kWho, path);
            std::exit(2);
        }
        return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    }
    std::vector<std::uint8_t> data;
    std::uint8_t buffer[4096];
    for (;;) {
        const ssize_t n = ::read(0, buffer, sizeof buffer);
        if (n <= 0) break;
        data.insert(data.end(), buffer, buffer + n);
    }
    return data;
}

// One input; a finding aborts.
void run_input_from(const char* path, std::uint8_t* map) {
    avrbench::fuzz::InputOutcome outcome;
    {
        const std::vector<std::uint8_t> input = read_input(path);
        if (avrbench::fuzz::target_restores()) {
            avrbench::fuzz::run_input_and_restore(input.data(), input.size(), map, kMapSize - 1, outcome);
        } else {
            avrbench::fuzz::run_input(input.data(), input.size(), map, kMapSize - 1, outcome);
        }
    }
    if (outcome.finding) {
        std::fprintf(stderr, "avrbench fuzz: FINDING after %llu AVR instructions: %s\n",
                     static_cast<unsigned long long>(outcome.steps), outcome.detail);
        std::fflush(stderr);
        std::abort();
    }
}

[[noreturn]] void run_one(const char* path, std::uint8_t* map) {
    run_input_from(path, map);
    std::_Exit(0);
}

// The persistent child: AFL writes each input to the same file (or to
// standard input, rewound), then resumes this process.
[[noreturn]] void run_persistent(const char* path, std::uint8_t* map) {
    for (int i = 1;; ++i) {
        if (path == nullptr) (void)::lseek(0, 0, SEEK_SET);
        run_input_from(path, map);
        // The last input's status is this exit (as AFL++'s own __AFL_LOOP
        // ends): stopping first would leave the next request answered by an
        // exit with no input run.
        if (i == kInputsPerChild) std::_Exit(0);
        ::raise(SIGSTOP);
    }
}

std::uint8_t* coverage_map() {
    if (const char* id = std::getenv("__AFL_SHM_ID"); id != nullptr && *id != '\0') {
        void* map = ::shmat(std::atoi(id), nullptr, 0);
        if (map == reinterpret_cast<void*>(-1)) {
            std::perror("fuzz_firmware_afl: shmat");
            std::exit(2);
        }
        return static_cast<std::uint8_t*>(map);
    }
    static std::vector<std::uint8_t> local(kMapSize);  // outside AFL: counted and dropped
    return local.data();
}

}  // namespace

int main(int argc, char** argv) {
    const char* path = argc > 1 ? argv[1] : nullptr;
    avrbench::fuzz::boot_target(avrbench::fuzz::config_from_environment(kWho, argv[0]), kWho);
    std::uint8_t* map = coverage_map();

    // The hello announces the map size (AFL++'s fork-server options: bit 31
    // and bit 0 say options follow, bit 30 a map size, bits 1..23 the size
    // minus one); without it AFL++ 4 would use an 8 MiB map, 128x the
    // bytes to classify per execution for the same edges.
    constexpr std::uint32_t kOptionsFollow = 0x80000001u;
    constexpr std::uint32_t kMapSizeOption = 0x40000000u;
    const std::uint32_t hello = kOptionsFollow | kMapSizeOption | ((kMapSize - 1) << 1);
    // Under AFL exactly when AFL's map is named and its status pipe takes the
    // hello; otherwise (a replay) one run, even if a shell left fd 199 open.
    const bool under_afl = std::getenv("__AFL_SHM_ID") != nullptr;
    if (!under_afl || ::write(kStatusFd, &hello, sizeof hello) != sizeof hello) run_one(path, map);

    const bool persistent = avrbench::fuzz::target_restores();
    pid_t child = -1;
    bool child_stopped = false;  // a persistent child waiting for its next input
    for (;;) {
        // The request says whether AFL killed the child (its timeout) since.
        std::uint32_t was_killed = 0;
        if (::read(kControlFd, &was_killed, sizeof was_killed) != sizeof was_killed) return 0;  // AFL is gone
        if (child_stopped && was_killed != 0) {
            child_stopped = false;
            int reaped = 0;
            if (::waitpid(child, &reaped, 0) < 0) return 2;
        }
        if (child_stopped) {
            child_stopped = false;
            ::kill(child, SIGCONT);
        } else {
            child = ::fork();
            if (child < 0) {
                std::perror("fuzz_firmware_afl: fork");
                return 2;
            }
            if (child == 0) {
                ::close(kControlFd);
                ::close(kStatusFd);
                if (persistent) run_persistent(path, map);
                run_one(path, map);
            }
        }
        const std::int32_t pid = child;
        if (::write(kStatusFd, &pid, sizeof pid) != sizeof pid) return 0;
        int status = 0;
        if (::waitpid(child, &status, persistent ? WUNTRACED : 0) < 0) return 2;
        child_stopped = WIFSTOPPED(status);
        const std::int32_t wait_status = status;
        if (::write(kStatusFd, &wait_status, sizeof wait_status) != sizeof wait_status) return 0;
    }
}
