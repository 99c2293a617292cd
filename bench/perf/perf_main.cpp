// avrbench_perf: measures what the bench costs on top of simavr.
//
// For each workload it runs the same ELF for the same simulated time
//   (a) through bare simavr: avr_make_mcu_by_name, avr_init,
//       avr_load_firmware and a plain `while (state ok) avr_run()` loop, as
//       simavr's own run_avr does, with simavr's sleep callback replaced by a
//       no-op (the raw one would usleep and measure the wall clock, not simavr);
//   (b) through avrbench: Mcu + Recorder tracing 8 pins + VCD written at the end;
// each timed from creating the core to tearing it down (the ELF is parsed once
// beforehand for both);
// alternating (a) and (b) several times and keeping each side's best wall
// time, then prints the ratio (b)/(a) and each side's real-time factor.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

extern "C" {
#include <sim_avr.h>
#include <sim_elf.h>
}

#include "core/ElfImage.hpp"
#include "core/Mcu.hpp"
#include "trace/Recorder.hpp"
#include "trace/VcdWriter.hpp"

namespace {

using Clock = std::chrono::steady_clock;

void no_wall_clock_sleep(avr_t*, avr_cycle_count_t) {}

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// (a) bare simavr, as run_avr drives it.
double run_bare_simavr(const avrbench::ElfImage& elf, avr_cycle_count_t cycles) {
    const auto start = Clock::now();
    elf_firmware_t firmware = elf.simavr_firmware();
    firmware.tracecount = 0;
    avr_t* avr = avr_make_mcu_by_name(firmware.mmcu);
    avr_init(avr);
    avr_load_firmware(avr, &firmware);
    avr->sleep = &no_wall_clock_sleep;
    int state = cpu_Running;
    while ((state == cpu_Running || state == cpu_Sleeping) && avr->cycle < cycles) state = avr_run(avr);
    avr_terminate(avr);
    std::free(avr);
    return seconds_since(start);
}

// (b) the bench with 8 traced pins and a VCD.
double run_avrbench(const avrbench::ElfImage& elf, avr_cycle_count_t cycles, const std::string& pins,
                    const std::string& vcd_path, std::size_t* events) {
    const auto start = Clock::now();
    avrbench::Mcu mcu(elf);
    avrbench::Timeline timeline;
    avrbench::Recorder recorder(timeline);
    recorder.trace_pins(mcu, pins);
    mcu.run_until(cycles);
    avrbench::VcdOptions options;
    options.end_cycle = mcu.cycle();
    options.end_clock_hz = mcu.frequency_hz();
    avrbench::write_vcd(timeline, vcd_path, options);
    *events = timeline.events().size();
    return seconds_since(start);
}

struct Workload {
    const char* name;
    const char* elf;
    const char* pins;  // 8 traced pins
    double simulated_s;
};

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"avrbench_perf: bench vs bare simavr on the same ELFs"};
    int repeats = 3;
    double scale = 1.0;
    std::string firmware_dir = AVRBENCH_FIRMWARE_DIR;
    app.add_option("--repeats", repeats, "runs per side (best is kept)");
    app.add_option("--scale", scale, "multiply every workload's simulated time");
    app.add_option("--firmware-dir", firmware_dir, "where the firmware ELFs are");
    CLI11_PARSE(app, argc, argv);

    const Workload workloads[] = {
        {"busy_poll (CPU-bound, PORTD counter)", "busy_poll", "PORTD", 5.0},
        {"blink_timer1 (timer ISR, idle loop)", "blink_timer1", "PORTB", 5.0},
        {"sleep_idle (SLEEP between 10 ms wake-ups)", "sleep_idle", "PORTB", 600.0},
    };
    const auto vcd_path = (std::filesystem::temp_directory_path() / "avrbench_perf.vcd").string();
    std::printf("%-44s %9s %12s %12s %9s %9s %7s\n", "workload", "sim s", "bare RTF", "bench RTF", "bare s",
                "bench s", "ratio");
    for (const auto& w : workloads) {
        const auto elf = avrbench::ElfImage::load(firmware_dir + "/" + w.elf + ".elf");
        const double simulated_s = w.simulated_s * scale;
        const auto cycles = static_cast<avr_cycle_count_t>(simulated_s * elf.embedded_frequency_hz());
        double best_bare = 1e300, best_bench = 1e300;
        std::size_t events = 0;
        for (int i = 0; i < repeats; ++i) {
            best_bare = std::min(best_bare, run_bare_simavr(elf, cycles));
            best_bench = std::min(best_bench, run_avrbench(elf, cycles, w.pins, vcd_path, &events));
        }
        std::printf("%-44s %9.1f %11.1fx %11.1fx %9.3f %9.3f %7.3f  (%zu trace events)\n", w.name, simulated_s,
                    simulated_s / best_bare, simulated_s / best_bench, best_bare, best_bench, best_bench / best_bare,
                    events);
    }
    std::filesystem::remove(vcd_path);
    return 0;
}
