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
//
// Then the thermal plant's cost (docs/THERMAL.md): the RAMPS PID firmware
// (thermal_pid) on a board with the hot end and bed plants, heaters,
// thermistors and the fan, against the same firmware on a board with only the
// MCU whose ADC replays the recorded thermistor voltages (so the firmware runs
// the very same instructions), same simulated time, best of --repeats each.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <string>

extern "C" {
#include <sim_avr.h>
#include <sim_elf.h>
}

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "core/Adc.hpp"
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

// The thermal plant's overhead: one board run, from building the board to
// tearing it down. The firmware must execute the same instructions on both
// sides, so the board without the plant replays, conversion by conversion,
// the voltages the plant produced (recorded in an untimed run): the difference
// in wall time is the plant parts' own cost (heater edges, thermistor samples,
// plant updates, sample ticks). Returns the wall time; `steps` gets the MCU's
// step count to show both sides ran the same program path.
struct AdcTape {
    std::vector<double> volts[16];
    std::size_t next[16] = {};
};

double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

double run_board(const std::string& yaml, const std::string& elf_path, double simulated_s, AdcTape* record,
                 AdcTape* replay, std::uint64_t* steps, double* cpu_s) {
    const auto start = Clock::now();
    const double cpu_start = thread_cpu_seconds();
    {
        avrbench::Board board(avrbench::parse_board_text(yaml, "perf.yaml"), {{"mega", elf_path}});
        avrbench::Adc& adc = board.mcu().adc();
        if (record != nullptr) {
            adc.on_sample([record](const avrbench::Adc::Sample& s) {
                if (s.channel >= 0 && s.channel < 16) record->volts[s.channel].push_back(s.volts);
            });
        }
        if (replay != nullptr) {
            for (int ch = 0; ch < 16; ++ch) {
                if (replay->volts[ch].empty()) continue;
                replay->next[ch] = 0;
                adc.connect(ch, [replay, ch](avrbench::Cycle) {
                    const auto& v = replay->volts[ch];
                    std::size_t& i = replay->next[ch];
                    return i < v.size() ? v[i++] : v.back();
                });
            }
        }
        board.run_until_seconds(simulated_s);
        *steps = board.mcu().steps();
    }
    *cpu_s = thread_cpu_seconds() - cpu_start;
    return seconds_since(start);
}

constexpr const char* kBareMegaBoard = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
)";

// ramps-1.4.yaml's thermal parts, nothing else.
constexpr const char* kThermalMegaBoard = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: e3d_v6}
  hotend_heater: {type: heater, preset: cartridge_40w_12v, plant: hotend}
  hotend_thermistor: {type: thermistor, preset: epcos_b57560g104f, plant: hotend, adc_pin: mega.PK5}
  part_fan: {type: fan, plant: hotend}
  bed: {type: thermal_plant, preset: heated_bed}
  bed_heater: {type: heater, preset: bed_12v, plant: bed}
  bed_thermistor: {type: thermistor, preset: epcos_b57560g104f, plant: bed, adc_pin: mega.PK6}
nets:
  hotend_heater_gate: [mega.PB4, hotend_heater.gate]
  part_fan_gate: [mega.PH6, part_fan.pwm]
  bed_heater_gate: [mega.PH5, bed_heater.gate]
)";

struct Workload {
    const char* name;
    const char* elf;
    const char* pins;  // 8 traced pins
    double simulated_s;
};

}  // namespace

// The coil-driven motor's overhead (perf_motor.cpp, docs/MOTOR.md).
void run_motor_overhead(const std::string& firmware_dir, const std::string& source_dir, int repeats, double scale);

int main(int argc, char** argv) {
    CLI::App app{"avrbench_perf: bench vs bare simavr on the same ELFs"};
    int repeats = 3;
    double scale = 1.0;
    std::string firmware_dir = AVRBENCH_FIRMWARE_DIR;
    app.add_option("--repeats", repeats, "runs per side (best is kept)");
    app.add_option("--scale", scale, "multiply every workload's simulated time");
    app.add_option("--firmware-dir", firmware_dir, "where the firmware ELFs are");
    bool only_thermal = false;
    app.add_flag("--only-thermal", only_thermal, "only the thermal plant's overhead");
    CLI11_PARSE(app, argc, argv);

    const Workload workloads[] = {
        {"busy_poll (CPU-bound, PORTD counter)", "busy_poll", "PORTD", 5.0},
        {"busy_poll_step (step pins PD2/PD3 held low)", "busy_poll_step", "PORTD", 5.0},
        {"blink_timer1 (timer ISR, idle loop)", "blink_timer1", "PORTB", 5.0},
        {"sleep_idle (SLEEP between 10 ms wake-ups)", "sleep_idle", "PORTB", 600.0},
    };
    const auto vcd_path = (std::filesystem::temp_directory_path() / "avrbench_perf.vcd").string();
    std::printf("%-44s %9s %12s %12s %9s %9s %7s\n", "workload", "sim s", "bare RTF", "bench RTF", "bare s",
                "bench s", "ratio");
    for (const auto& w : workloads) {
        if (only_thermal) break;
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

    // Thermal plant overhead on the same firmware and simulated time.
    const std::string pid_elf = firmware_dir + "/thermal_pid.elf";
    const double thermal_s = 300.0 * scale;
    AdcTape tape;
    std::uint64_t steps_with = 0, steps_without = 0;
    double cpu = 0, cpu_without = 1e300, cpu_with = 1e300;
    run_board(kThermalMegaBoard, pid_elf, thermal_s, &tape, nullptr, &steps_with, &cpu);  // records the inputs
    double best_without = 1e300, best_with = 1e300;
    for (int i = 0; i < repeats; ++i) {
        best_without = std::min(best_without,
                                run_board(kBareMegaBoard, pid_elf, thermal_s, nullptr, &tape, &steps_without, &cpu));
        cpu_without = std::min(cpu_without, cpu);
        best_with = std::min(best_with, run_board(kThermalMegaBoard, pid_elf, thermal_s, nullptr, nullptr, &steps_with, &cpu));
        cpu_with = std::min(cpu_with, cpu);
    }
    // The plant side takes a few more run-loop steps: its sample ticks split
    // some SLEEP fast-forwards in two (about 20 per simulated second).
    std::printf("\n(run-loop steps: %llu without the plant, %llu with it)",
                static_cast<unsigned long long>(steps_without), static_cast<unsigned long long>(steps_with));
    std::printf("\n%-44s %9s %12s %12s %9s %9s %7s\n", "thermal plant (thermal_pid, ATmega2560)", "sim s",
                "no plant RTF", "plant RTF", "no pl. s", "plant s", "ratio");
    std::printf("%-44s %9.1f %11.1fx %11.1fx %9.3f %9.3f %7.3f\n", "hot end + bed plants, heaters, NTCs, fan",
                thermal_s, thermal_s / best_without, thermal_s / best_with, best_without, best_with,
                best_with / best_without);
    std::printf("%-44s %9s %12s %12s %9.3f %9.3f %7.3f\n", "  (thread CPU time, best of each)", "", "", "",
                cpu_without, cpu_with, cpu_with / cpu_without);
    if (!only_thermal) run_motor_overhead(firmware_dir, AVRBENCH_SOURCE_DIR, repeats, scale);
    return 0;
}
