// The coil-driven motor's cost (docs/MOTOR.md, docs/PERFORMANCE.md): seed
// 003's sketch_06 as written (Arduino delay() busy loops, AFMotor stepping a
// 74HC595 and two L293Ds on the Adafruit Motor Shield v1) for the same
// simulated time on the shield's board (a) without the motor part and (b)
// with the SM-42BYG011-25 on it, best wall time of --repeats runs each,
// alternating. The motor turns all the time (50 rpm and up). Then, for
// scale, the same motor under a firmware that sleeps between steps
// (motor_sweep_double), where the motor is nearly all the cost.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <string>

#include "CpuTime.hpp"
#include "boards/Board.hpp"
#include "parts/HybridStepper.hpp"

namespace {

using Clock = std::chrono::steady_clock;

using avrbench_perf::thread_cpu_seconds;

struct Times {
    double wall, cpu;
};

avrbench::BoardSpec shield(const std::string& source_dir, bool with_motor) {
    avrbench::BoardSpec spec = avrbench::load_board_file(source_dir + "/bench/boards/arduino-uno-motor-shield-v1.yaml");
    if (!with_motor) {
        spec.parts.erase(std::remove_if(spec.parts.begin(), spec.parts.end(),
                                        [](const avrbench::PartDecl& p) { return p.name == "motor"; }),
                         spec.parts.end());
        // and the net that joins its windings to the bridge
        spec.nets.erase(std::remove_if(spec.nets.begin(), spec.nets.end(),
                                       [](const avrbench::NetDecl& n) {
                                           for (const auto& e : n.endpoints) {
                                               if (e.owner == "motor") return true;
                                           }
                                           return false;
                                       }),
                        spec.nets.end());
    }
    return spec;
}

Times run(const std::string& source_dir, const std::string& elf, bool with_motor, double simulated_s,
          std::uint64_t* rk4_steps) {
    const auto start = Clock::now();
    const double cpu_start = thread_cpu_seconds();
    {
        avrbench::Board board(shield(source_dir, with_motor), {{"uno", elf}});
        board.run_until_seconds(simulated_s);
        if (with_motor) *rk4_steps = board.part_as<avrbench::HybridStepper>("motor").model().rk4_steps();
    }
    return {std::chrono::duration<double>(Clock::now() - start).count(), thread_cpu_seconds() - cpu_start};
}

}  // namespace

void run_motor_overhead(const std::string& firmware_dir, const std::string& source_dir, int repeats, double scale) {
    std::printf("\n%-44s %9s %12s %12s %9s %9s %7s\n", "coil-driven motor (Motor Shield v1)", "sim s", "no motor",
                "with motor", "no mot s", "motor s", "ratio");
    struct Workload {
        const char* name;
        const char* elf;
        double simulated_s;
    };
    const Workload workloads[] = {
        {"sketch06 (delay() loops, AFMotor, 50+ rpm)", "sketch06", 5.0},
        {"motor_sweep_double (SLEEP between steps)", "motor_sweep_double", 20.0},
    };
    for (const auto& w : workloads) {
        const std::string elf = firmware_dir + "/" + w.elf + ".elf";
        const double simulated_s = w.simulated_s * scale;
        double best_without = 1e300, best_with = 1e300, cpu_without = 1e300, cpu_with = 1e300;
        std::uint64_t rk4 = 0;
        for (int i = 0; i < repeats; ++i) {
            const Times a = run(source_dir, elf, false, simulated_s, &rk4);
            const Times b = run(source_dir, elf, true, simulated_s, &rk4);
            best_without = std::min(best_without, a.wall);
            cpu_without = std::min(cpu_without, a.cpu);
            best_with = std::min(best_with, b.wall);
            cpu_with = std::min(cpu_with, b.cpu);
        }
        std::printf("%-44s %9.1f %11.1fx %11.1fx %9.3f %9.3f %7.3f  (%llu RK4 steps)\n", w.name, simulated_s,
                    simulated_s / best_without, simulated_s / best_with, best_without, best_with,
                    best_with / best_without, static_cast<unsigned long long>(rk4));
        std::printf("%-44s %9s %12s %12s %9.3f %9.3f %7.3f\n", "  (thread CPU time, best of each)", "", "", "",
                    cpu_without, cpu_with, cpu_with / cpu_without);
    }
}
