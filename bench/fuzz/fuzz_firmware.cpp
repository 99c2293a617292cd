// libFuzzer target for firmware: G-code (or any bytes) into a board's
// serial port, coverage taken from the firmware's own program counter.
//
// Configured by the environment (avrbench fuzz and ci/fuzz set it):
//   AVRBENCH_FUZZ_BOARD  board file or standard board name (single-MCU boards)
//   AVRBENCH_FUZZ_ELF    the firmware
//   AVRBENCH_FUZZ_FAMILY the host's firmware family (grbl, marlin, teacup,
//                        generic) when not the board's serial port's
//   AVRBENCH_FUZZ_BOUND  simulated seconds one input may take (default 3)
//   AVRBENCH_FUZZ_SEEN   a file of the finding kinds already reported in the
//                        campaign (FuzzFindings.hpp): an input whose finding
//                        is of a kind listed there is not a crash, so a job
//                        is not stopped and restarted for the same bug again
//   AVRBENCH_FUZZ_RAW    1: the input's bytes go to the serial port as they
//                        are, for binary protocols (seed 002's records): no
//                        host, so no banner to wait for (the firmware boots
//                        for AVRBENCH_FUZZ_BOOT seconds, default 0.2) and no
//                        hang oracle; the run ends the settle time after the
//                        last byte went in
//   AVRBENCH_FUZZ_SETTLE simulated seconds to keep running after the last
//                        answer, for what the lines set in motion (default 0.1:
//                        five RC-servo frames)
//
// Once, at start-up, the firmware boots on the board until its host sees the
// family's banner (the board's serial port says which: grbl, marlin, teacup).
// Then per input the process forks: the child sends the input's lines,
// steps the MCU instruction by instruction and counts every program-counter
// edge (previous PC, PC) into a map shared with the parent; the parent copies
// the map into libFuzzer's extra counters, so the search follows the
// firmware's branches, not the bench's. Booting once and forking keeps an
// execution to the input's own simulated time.
//
// Oracles (a finding aborts, and libFuzzer keeps the input as crash-*):
// every finding the MCU and board raise during the input (bad opcode, PC
// outside the program, stack into .bss, watchdog reset, bad interrupt, net
// faults, part limits); a line the firmware never answers within the serial
// port's line timeout (a hang); a fatal answer ("!!"). "error" answers and
// restarts the firmware announces (grbl's ^X) are not findings.
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
#include "core/Errors.hpp"
#include "verify/Bench.hpp"

namespace {

constexpr std::size_t kMapSize = 1u << 16;
constexpr std::size_t kDetailBytes = 512;

struct Shared {
    std::uint8_t edges[kMapSize];
    std::uint32_t finding;  // 0: none
    std::uint64_t steps;
    char detail[kDetailBytes];
};

// libFuzzer reads every byte of this section as a coverage counter.
__attribute__((section("__libfuzzer_extra_counters"), used)) std::uint8_t g_counters[kMapSize];

// Never destroyed: at exit the fixes' registries (function-local statics)
// may go first, and the process is ending anyway.
avrbench::Bench* g_bench = nullptr;
Shared* g_shared = nullptr;
double g_bound_s = 3.0;
double g_settle_s = 0.1;
bool g_raw = false;
std::size_t g_findings_at_ready = 0;

const char* env_or_die(const char* name) {
    const char* value = std::getenv(name);
    if (value == nullptr || *value == '\0') {
        std::fprintf(stderr, "fuzz_firmware: set %s (see bench/fuzz/fuzz_firmware.cpp)\n", name);
        std::exit(2);
    }
    return value;
}

// A restart mid-job is not one: grbl's ^X restarts on purpose, and a reset
// the firmware did not ask for is already an MCU finding (watchdog, jump to 0).
bool is_oracle_event(avrbench::HostEventKind kind) {
    return kind == avrbench::HostEventKind::Timeout || kind == avrbench::HostEventKind::Fatal;
}

// In the child: run the input, fill g_shared.
void run_child(const std::uint8_t* data, std::size_t size) {
    avrbench::Bench& bench = *g_bench;
    avrbench::Mcu& mcu = bench.mcu();
    avrbench::UartHost* host = g_raw ? nullptr : &bench.host();
    avrbench::Uart& serial = bench.serial();
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    if (host != nullptr) {
        try {
            host->add_lines(bytes);
        } catch (const avrbench::BadInput&) {
            return;  // nothing the host would send (it refuses such a job up front)
        }
    } else {
        serial.send(bytes);
    }
    // Done sending: every line answered (or the host gave up), or every raw byte taken.
    const auto sent = [&] { return host != nullptr ? host->finished() : serial.pending_rx() == 0; };
    avrbench::Cycle end = mcu.cycle() + mcu.cycles_from_seconds(g_bound_s);
    // The run loop with coverage (Mcu::run_until_covering), in slices of 1 ms
    // simulated between which the settle time may start.
    avrbench::PcEdgeMap edges{g_shared->edges, kMapSize - 1};
    const avrbench::Cycle slice = mcu.cycles_from_seconds(0.001);
    const std::uint64_t steps_before = mcu.steps();
    bool settling = false;
    while (mcu.cycle() < end && !mcu.halted()) {
        if (!settling && sent()) {
            settling = true;
            end = std::min(end, mcu.cycle() + mcu.cycles_from_seconds(g_settle_s));
        }
        mcu.run_until_covering(std::min(end, mcu.cycle() + slice), edges);
    }
    const std::uint64_t steps = mcu.steps() - steps_before;
    g_shared->steps = steps;
    std::string detail;
    const auto findings = bench.board().findings();  // the MCU's, the nets', the parts'
    if (findings.size() > g_findings_at_ready) detail = findings[g_findings_at_ready].describe();
    if (detail.empty() && host != nullptr) {
        for (const auto& e : host->events()) {
            if (is_oracle_event(e.kind)) {
                detail = std::string(avrbench::to_string(e.kind)) + ": " + e.message;
                break;
            }
        }
    }
    if (!detail.empty()) {
        g_shared->finding = 1;
        std::snprintf(g_shared->detail, kDetailBytes, "%s", detail.c_str());
    }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    const std::string board = env_or_die("AVRBENCH_FUZZ_BOARD");
    const std::string elf = env_or_die("AVRBENCH_FUZZ_ELF");
    if (const char* bound = std::getenv("AVRBENCH_FUZZ_BOUND")) g_bound_s = std::max(0.01, std::atof(bound));
    if (const char* settle = std::getenv("AVRBENCH_FUZZ_SETTLE")) g_settle_s = std::max(0.0, std::atof(settle));
    if (const char* raw = std::getenv("AVRBENCH_FUZZ_RAW")) g_raw = std::string(raw) == "1";
    try {
        g_bench = new avrbench::Bench(board, elf);
        if (g_bench->board().mcus().size() != 1) {
            std::fprintf(stderr, "fuzz_firmware: %s has %zu MCUs; the fuzz target steps one\n", board.c_str(),
                         g_bench->board().mcus().size());
            std::exit(2);
        }
        avrbench::Mcu& mcu = g_bench->mcu();
        if (g_raw) {
            double boot_s = 0.2;
            if (const char* boot = std::getenv("AVRBENCH_FUZZ_BOOT")) boot_s = std::max(0.0, std::atof(boot));
            (void)g_bench->serial();  // the USART model listens from here on
            g_bench->run_for(boot_s);
        } else {
            avrbench::UartHostOptions options = avrbench::default_host_options(g_bench->serial_decl());
            if (const char* family = std::getenv("AVRBENCH_FUZZ_FAMILY"); family != nullptr && *family != '\0') {
                options.family = avrbench::parse_firmware_family(family, "AVRBENCH_FUZZ_FAMILY");
            }
            avrbench::UartHost& host = g_bench->host("", options);
            const avrbench::Cycle limit = mcu.cycle() + mcu.cycles_from_seconds(host.options().banner_timeout_s + 0.5);
            while (!host.ready() && !host.failed() && !mcu.halted() && mcu.cycle() < limit) g_bench->run_for(0.001);
            if (!host.ready()) {
                std::fprintf(stderr, "fuzz_firmware: %s never became ready on %s (%s)\n", elf.c_str(), board.c_str(),
                             host.failed() ? host.failure_message().c_str() : "no banner");
                std::exit(2);
            }
        }
        g_findings_at_ready = g_bench->board().findings().size();
    } catch (const avrbench::BadInput& e) {
        std::fprintf(stderr, "fuzz_firmware: %s\n", e.what());
        std::exit(2);
    }
    void* shared = ::mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (shared == MAP_FAILED) {
        std::perror("fuzz_firmware: mmap");
        std::exit(2);
    }
    g_shared = static_cast<Shared*>(shared);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::memset(g_shared, 0, sizeof(Shared));
    const pid_t child = ::fork();
    if (child < 0) {
        std::perror("fuzz_firmware: fork");
        std::abort();
    }
    if (child == 0) {
        run_child(data, size);
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
    if (g_shared->finding != 0) {
        char line[kDetailBytes + 96];
        std::snprintf(line, sizeof line, "avrbench fuzz: FINDING after %llu AVR instructions: %s",
                      static_cast<unsigned long long>(g_shared->steps), g_shared->detail);
        if (const char* seen = std::getenv("AVRBENCH_FUZZ_SEEN"); seen != nullptr && *seen != '\0') {
            const std::string kind = avrbench::finding_kind(line);
            std::ifstream in(seen);
            for (std::string known; std::getline(in, known);) {
                // Reported already: keep fuzzing, but keep the input out of the
                // corpus (-1), or inputs that crash at once would crowd it.
                if (known == kind) return -1;
            }
            // One short append (O_APPEND): jobs running side by side do not mix lines.
            const int fd = ::open(seen, O_WRONLY | O_CREAT | O_APPEND, 0644);
            if (fd >= 0) {
                const std::string entry = kind + "\n";
                (void)!::write(fd, entry.data(), entry.size());
                ::close(fd);
            }
        }
        std::fprintf(stderr, "%s\n", line);
        std::abort();
    }
    return 0;
}

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
    if (g_raw) return LLVMFuzzerMutate(data, size, max_size);  // a binary protocol: bytes, not G-code
    return avrbench::fuzz::mutate_gcode(data, size, max_size, seed);
}
