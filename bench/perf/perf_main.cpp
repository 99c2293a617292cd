// avrbench_perf: measures what the bench costs on top of simavr.
//
// For each workload it runs the same ELF for the same simulated time
//   (a) through bare simavr configured as a careful user would:
//       avr_make_mcu_by_name, avr_init, avr_load_firmware, the external
//       interrupts' strict level polling off (avr_extint_set_strict_lvl_trig,
//       which otherwise re-raises a held low level on every instruction), the
//       USARTs' poll-sleep and stdio echo flags cleared (AVR_IOCTL_UART_SET_FLAGS), a
//       no-op sleep callback (the raw one usleep()s to keep wall-clock pace),
//       and a plain `while (state ok) avr_run()` loop, as run_avr does;
//   (b) through avrbench as `avrbench run --vcd` runs it: Mcu with its
//       fixes and oracles, every pin and USART0 traced, the VCD streamed to a
//       file every 10 ms of simulated time;
// each timed in thread CPU time from creating the core to tearing it down
// (the ELF is parsed once beforehand for both), alternating (a) and (b)
// --repeats times; the medians are printed with their ratio (b)/(a).
// `--workload NAME --side bare|bench` runs one side once, for
// instruction counts under callgrind (bench/perf/instructions).
//
// Then the thermal plant's cost (docs/THERMAL.md): the RAMPS PID firmware
// (thermal_pid) on a board with the hot end and bed plants, heaters,
// thermistors and the fan, against the same firmware on a board with only the
// MCU whose ADC replays the recorded thermistor voltages (so the firmware runs
// the very same instructions), same simulated time, best of --repeats each.
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <string>

extern "C" {
#include <avr_extint.h>
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_elf.h>
}

#include "CpuTime.hpp"
#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "periph/adc/Adc.hpp"
#include "mcu/ElfImage.hpp"
#include "mcu/Lockstep.hpp"
#include "mcu/Mcu.hpp"
#include "trace/Recorder.hpp"
#include "trace/VcdWriter.hpp"
#include "verify/TimelineCompare.hpp"

namespace {

using Clock = std::chrono::steady_clock;

void no_wall_clock_sleep(avr_t*, avr_cycle_count_t) {}

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

using avrbench_perf::thread_cpu_seconds;

// (a) bare simavr, as run_avr drives it, strict level polling off. Returns CPU seconds.
__attribute__((noinline)) double run_bare_simavr(const avrbench::ElfImage& elf, avr_cycle_count_t cycles,
                                                 const avrbench::McuOptions& given = {}) {
    const double start = thread_cpu_seconds();
    elf_firmware_t firmware = elf.simavr_firmware();
    firmware.tracecount = 0;
    if (!given.mcu_type.empty()) std::snprintf(firmware.mmcu, sizeof firmware.mmcu, "%s", given.mcu_type.c_str());
    if (given.frequency_hz != 0) firmware.frequency = given.frequency_hz;
    avr_t* avr = avr_make_mcu_by_name(firmware.mmcu);
    avr_init(avr);
    avr_load_firmware(avr, &firmware);
    avr->sleep = &no_wall_clock_sleep;
    for (std::uint8_t line = 0; line < 8; ++line) avr_extint_set_strict_lvl_trig(avr, line, 0);
    // Nor should every UCSRnA read usleep(1) (AVR_UART_FLAG_POLL_SLEEP, on by
    // default) or received bytes be echoed to stdout.
    for (char uart = '0'; uart <= '3'; ++uart) {
        std::uint32_t flags = 0;
        if (avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS(uart), &flags) < 0) continue;
        flags &= ~static_cast<std::uint32_t>(AVR_UART_FLAG_POLL_SLEEP | AVR_UART_FLAG_STDIO);
        avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS(uart), &flags);
    }
    int state = cpu_Running;
    while ((state == cpu_Running || state == cpu_Sleeping) && avr->cycle < cycles) state = avr_run(avr);
    avr_terminate(avr);
    std::free(avr);
    return thread_cpu_seconds() - start;
}

// (b) the bench as `avrbench run --vcd` runs it. Returns CPU seconds.
__attribute__((noinline)) double run_avrbench(const avrbench::ElfImage& elf, avr_cycle_count_t cycles,
                                              const std::string& vcd_path, std::uint64_t* events,
                                              const avrbench::McuOptions& given = {}) {
    const double start = thread_cpu_seconds();
    {
        avrbench::Mcu mcu(elf, given);
        avrbench::Timeline timeline;
        avrbench::Recorder recorder(timeline);
        recorder.trace_pins(mcu, "all");
        recorder.trace_uart_tx(mcu, mcu.uart(0));
        avrbench::VcdStream vcd(timeline, vcd_path);
        const avr_cycle_count_t slice = mcu.frequency_hz() / 100;  // 10 ms, as the CLI
        while (mcu.cycle() < cycles) {
            if (mcu.run_until(std::min(cycles, mcu.cycle() + slice)) == avrbench::StopReason::Halted) break;
            vcd.drain(timeline, avrbench::ps_at_cycle(mcu, mcu.cycle()));
        }
        avrbench::VcdOptions options;
        options.end_cycle = mcu.cycle();
        options.end_clock_hz = mcu.frequency_hz();
        vcd.finish(timeline, options);
        *events = timeline.recorded_count();
    }
    return thread_cpu_seconds() - start;
}

using avrbench_perf::median;

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
  hotend_heater: {type: heater, preset: cartridge_40w_12v}
  hotend_thermistor: {type: thermistor, preset: epcos_b57560g104f}
  part_fan: {type: fan}
  bed: {type: thermal_plant, preset: heated_bed}
  bed_heater: {type: heater, preset: bed_12v}
  bed_thermistor: {type: thermistor, preset: epcos_b57560g104f}
nets:
  hotend_body: [hotend.body, hotend_heater.body, hotend_thermistor.body, part_fan.body]
  bed_body: [bed.body, bed_heater.body, bed_thermistor.body]
  hotend_thermistor_adc: [mega.PK5, hotend_thermistor.out]
  bed_thermistor_adc: [mega.PK6, bed_thermistor.out]
  hotend_heater_gate: [mega.PB4, hotend_heater.gate]
  part_fan_gate: [mega.PH6, part_fan.pwm]
  bed_heater_gate: [mega.PH5, bed_heater.gate]
)";

// Every comparison rule on `edges` edges: a golden and an actual timeline,
// each a wire toggling every 100 cycles (a 80 kHz step train at 16 MHz) and
// a real signal changing as often; the actual's wire moved by 1 cycle so the
// tolerant rules have something to tolerate. Prints edges per CPU second.
void run_compare_rows(std::size_t edges) {
    using namespace avrbench;
    auto make = [edges](Cycle shift) {
        Timeline t;
        const SignalId wire = t.add_signal({"m", "step", SignalKind::Wire, 1, 16000000});
        const SignalId real = t.add_signal({"plant", "degC", SignalKind::Real, 1, 16000000});
        t.reserve_events(2 * edges);
        for (std::size_t i = 0; i < edges; ++i) {
            t.record(wire, 100 * i + (i > 0 ? shift : 0), i % 2);
            t.record_real(real, 100 * i, 25.0 + static_cast<double>(i % 1000) * 0.01);
        }
        return t;
    };
    const Timeline golden = make(0), actual = make(1);
    struct Row {
        const char* name;
        ChannelRule rule;
    };
    const Row rows[] = {
        {"exact", {"*", RuleKind::Exact}},
        {"timing (2 cycles)", {"*", RuleKind::Timing, 2}},
        {"steps (2 cycles)", {"*", RuleKind::Steps, 2}},
        {"step_rate (1 ms windows)", {"*", RuleKind::StepRate, 0, 0.05, 0.001}},
        {"pwm_duty (1 ms windows)", {"*", RuleKind::PwmDuty, 0, 0, 0.001, 0.05}},
        {"band (0.1)", {"*", RuleKind::Band, 0, 0, 0.01, 0.1}},
    };
    std::printf("\n%-44s %12s %12s %14s\n", "comparison rule (2 signals x edges each side)", "edges", "CPU s",
                "edges/s");
    for (const Row& row : rows) {
        CompareOptions options;
        options.rules = {row.rule};
        const double start = thread_cpu_seconds();
        const CompareResult result = compare_timelines(golden, actual, options);
        const double cpu = thread_cpu_seconds() - start;
        const double total = 2.0 * 2.0 * static_cast<double>(edges);  // both timelines, both signals
        std::printf("%-44s %12zu %12.3f %13.1fM  (%s)\n", row.name, edges, cpu, total / cpu / 1e6,
                    result.passed ? "passed" : "differs");
    }
}

struct Workload {
    const char* name;
    const char* elf;
    double simulated_s;
};

// Peak resident memory of `avrbench run <elf> --for <seconds>s --trace-only PB0
// --vcd <tmp>` in a child process (getrusage of the child), in MiB.
double cli_peak_rss_mib(const std::string& elf, double seconds, const std::string& vcd_path) {
    const std::string for_arg = std::to_string(seconds) + "s";
    const pid_t pid = fork();
    if (pid == 0) {
        const int null_fd = open("/dev/null", O_WRONLY);
        dup2(null_fd, STDOUT_FILENO);
        execl(AVRBENCH_CLI, AVRBENCH_CLI, "run", "-q", elf.c_str(), "--for", for_arg.c_str(), "--trace-only", "PB0", "--vcd",
              vcd_path.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    if (wait4(pid, &status, 0, &usage) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
    return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace

namespace avrbench_perf {
// perf_qemu.cpp
std::string qemu_version();
double qemu_cpu_seconds(const std::string& elf, std::uint32_t from_addr, std::uint32_t to_addr, std::string& why,
                        bool stop_on_entry = false);
}  // namespace avrbench_perf

// The coil-driven motor's overhead (perf_motor.cpp, docs/MOTOR.md).
void run_motor_overhead(const std::string& firmware_dir, const std::string& source_dir, int repeats, double scale);
void run_printer_lockstep(const std::string& firmware_dir, const std::string& source_dir, int repeats, bool strict_row);
void run_printer_part_once(const std::string& firmware_dir, const std::string& source_dir);
void run_fast_forward(const std::string& firmware_dir, const std::string& source_dir, int repeats, double scale);

// The workloads of the side-by-side table: bare simavr and the bench on the same ELF.
const Workload kWorkloads[] = {
    {"busy_poll (CPU-bound, PORTD counter)", "busy_poll", 5.0},
    {"busy_poll_step (step pins PD2/PD3 held low)", "busy_poll_step", 5.0},
    {"blink_timer1 (timer ISR, idle loop)", "blink_timer1", 5.0},
    {"toggle_1mhz (PB0 edge every us: 1 M events/s)", "toggle_1mhz", 2.0},
    {"grbl_stepper (grbl-style step ISR, idle)", "grbl_stepper", 5.0},
    {"ramps_teacup (Teacup-style RAMPS, 2560)", "ramps_teacup", 5.0},
    {"sleep_idle (SLEEP between 10 ms wake-ups)", "sleep_idle", 600.0},
};

// --workload W --side S: one side once (callgrind counts its instructions).
int run_one_side(const std::string& only_workload, const std::string& side, const std::string& firmware_dir, double scale,
                 const std::string& vcd_path) {
    for (const auto& w : kWorkloads) {
        if (only_workload != w.elf) continue;
        const auto elf = avrbench::ElfImage::load(firmware_dir + "/" + w.elf + ".elf");
        const auto cycles = static_cast<avr_cycle_count_t>(w.simulated_s * scale * elf.embedded_frequency_hz());
        std::uint64_t events = 0;
        const double cpu = side == "bare" ? run_bare_simavr(elf, cycles) : run_avrbench(elf, cycles, vcd_path, &events);
        std::printf("%s %s %.3f s CPU\n", w.elf, side.c_str(), cpu);
        std::filesystem::remove(vcd_path);
        return 0;
    }
    std::fprintf(stderr, "avrbench_perf: no workload '%s'\n", only_workload.c_str());
    return 2;
}

// --elf: a firmware built outside this repository (grbl, Teacup, Marlin...),
// idle on both sides: no host, no board, same simulated time.
void run_external_elf(const std::string& external_elf, const std::string& external_mcu, double external_seconds, int repeats,
                      const std::string& vcd_path) {
    avrbench::McuOptions options;
    options.mcu_type = external_mcu;
    options.frequency_hz = 16'000'000;
    const auto elf = avrbench::ElfImage::load(external_elf);
    const auto cycles = static_cast<avr_cycle_count_t>(external_seconds * options.frequency_hz);
    std::vector<double> bare, bench;
    std::uint64_t events = 0;
    for (int i = 0; i < repeats; ++i) {
        bare.push_back(run_bare_simavr(elf, cycles, options));
        bench.push_back(run_avrbench(elf, cycles, vcd_path, &events, options));
    }
    const double b = median(bare), a = median(bench);
    std::printf("%s (%s, 16 MHz), %.1f s simulated: bare %.1fx real time (%.3f s CPU), bench %.1fx (%.3f s), "
                "ratio %.3f, %llu trace events\n",
                external_elf.c_str(), external_mcu.c_str(), external_seconds, external_seconds / b, b,
                external_seconds / a, a, a / b, static_cast<unsigned long long>(events));
    std::filesystem::remove(vcd_path);
}

// Peak resident memory of the CLI run with `args` in `dir` (a child process,
// getrusage of the child), in MiB; -1 if it failed to run. Exit codes in
// `accepted_exits` count as having run (a failed check exits 1).
double cli_run_peak_rss_mib(const std::vector<std::string>& args, const std::string& dir, std::initializer_list<int> accepted_exits) {
    const pid_t pid = fork();
    if (pid == 0) {
        const int null_fd = open("/dev/null", O_WRONLY);
        dup2(null_fd, STDOUT_FILENO);
        if (chdir(dir.c_str()) != 0) _exit(127);
        std::vector<char*> argv{const_cast<char*>(AVRBENCH_CLI)};
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(AVRBENCH_CLI, argv.data());
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    if (wait4(pid, &status, 0, &usage) != pid || !WIFEXITED(status)) return -1;
    if (std::find(accepted_exits.begin(), accepted_exits.end(), WEXITSTATUS(status)) == accepted_exits.end()) return -1;
    return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// --check-rss: `avrbench check` of a scenario whose golden holds `edges`
// edges of one wire (toggle_1mhz's PB0, 1 M edges per simulated second):
// plain (the run streamed into the comparison), failing at the first edge
// (the diff's context read back from the held changes), with --vcd-dir
// (streamed too) and with --report-dir (the run held whole for the report),
// beside `golden update`.
void run_check_rss(std::size_t edges, const std::string& firmware_dir) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("avrbench_perf_check_" + std::to_string(getpid()));
    const std::string firmware = fs::absolute(firmware_dir).string();  // the scenarios are read from `dir`
    fs::create_directories(dir / "golden");
    std::FILE* board = std::fopen((dir / "board.yaml").c_str(), "w");
    std::fputs("board: toggle-board\ndescription: an ATmega328P whose PB0 is labelled, so traced\n"
               "mcus:\n  uno: {type: atmega328p, clock: 16MHz}\nlabels:\n  toggle: uno.PB0\n", board);
    std::fclose(board);
    const double seconds = static_cast<double>(edges) / 1e6;
    auto scenario = [&](const std::string& name, const std::string& golden) {
        std::FILE* f = std::fopen((dir / (name + ".yaml")).c_str(), "w");
        std::fprintf(f, "name: %s\nboard: board.yaml\nfirmware: {uno: %s/toggle_1mhz.elf}\ntime_limit: %.6fs\n"
                        "steps:\n  - delay: %.6fs\ngolden: golden/%s.timeline\n",
                     name.c_str(), firmware.c_str(), seconds + 1, seconds, golden.c_str());
        std::fclose(f);
    };
    scenario("toggle", "toggle");
    scenario("shifted", "shifted");
    std::printf("%-58s %12s %14s\n", "avrbench on toggle_1mhz's PB0", "edges", "peak RSS MiB");
    const double update = cli_run_peak_rss_mib({"golden", "update", "toggle.yaml"}, dir.string(), {0});
    std::printf("%-58s %12zu %14.1f\n", "golden update", edges, update);
    // The shifted golden: its first rising edge one cycle early.
    {
        std::FILE* in = std::fopen((dir / "golden" / "toggle.timeline").c_str(), "r");
        std::FILE* out = std::fopen((dir / "golden" / "shifted.timeline").c_str(), "w");
        char line[512];
        bool shifted = false;
        while (in != nullptr && out != nullptr && std::fgets(line, sizeof line, in) != nullptr) {
            unsigned long long delta = 0;
            if (!shifted && std::sscanf(line, "+%llu 1\n", &delta) == 1 && delta > 1) {
                std::fprintf(out, "+%llu 1\n", delta - 1);
                shifted = true;
                continue;
            }
            std::fputs(line, out);
        }
        if (in != nullptr) std::fclose(in);
        if (out != nullptr) std::fclose(out);
    }
    const double check = cli_run_peak_rss_mib({"check", "toggle.yaml"}, dir.string(), {0});
    std::printf("%-58s %12zu %14.1f\n", "check (passes; the run streamed into the comparison)", edges, check);
    const double fails = cli_run_peak_rss_mib({"check", "shifted.yaml"}, dir.string(), {1});
    std::printf("%-58s %12zu %14.1f\n", "check (differs at the first rising edge)", edges, fails);
    const double vcd = cli_run_peak_rss_mib({"check", "toggle.yaml", "--vcd-dir", "vcd"}, dir.string(), {0});
    std::printf("%-58s %12zu %14.1f\n", "check --vcd-dir (the VCD written as the run goes)", edges, vcd);
    const double held = cli_run_peak_rss_mib({"check", "toggle.yaml", "--report-dir", "report"}, dir.string(), {0});
    std::printf("%-58s %12zu %14.1f\n", "check --report-dir (the run held whole for the report)", edges, held);
    std::error_code ec;
    fs::remove_all(dir, ec);
}

// --mips: MIPS on the same ELF, busy_poll_passes (busy_poll's loop for a
// fixed 20 M passes, then power-down with interrupts off at busy_poll_done):
// the bench as (b) runs it (every pin traced, the VCD streamed), the same on
// simavr's avr_run_one instead of the predecoded core, bare simavr
// as (a), and qemu-system-avr (perf_qemu.cpp: from main to busy_poll_done,
// QEMU's TCG, not cycle-exact). The instructions are the bench's count to
// the end (all three run the same program to the same place); CPU seconds,
// median of `repeats` interleaved runs of each.
// One program run to its end on every side, `repeats` interleaved times:
// the instructions and cycles to its end (the bench's count) and each
// side's median CPU seconds (qemu's < 0 when it cannot run: `why`).
struct SideTimes {
    std::uint64_t instructions = 0;
    avr_cycle_count_t cycles = 0;
    double bench = 0, bench_interpreted = 0, bench_simavr_core = 0, bare = 0, qemu = -1;
    std::string why;
};

SideTimes time_program(const std::string& path, const std::string& done_symbol, int repeats, const std::string& vcd_path,
                       bool with_qemu) {
    SideTimes t;
    const auto elf = avrbench::ElfImage::load(path);
    const auto main_addr = elf.symbol_address("main"), done_addr = elf.symbol_address(done_symbol);
    if (!main_addr || !done_addr) {
        t.why = path + " has no main or " + done_symbol;
        return t;
    }
    {
        avrbench::Mcu mcu(elf);
        while (mcu.run_until(mcu.cycle() + mcu.frequency_hz()) != avrbench::StopReason::Halted) {
        }
        t.instructions = mcu.steps();
        t.cycles = mcu.cycle();
    }
    std::vector<double> bare, bench, bench_interpreted, bench_simavr_core, emu;
    std::uint64_t events = 0;
    avrbench::McuOptions simavr_core, interpreted;
    simavr_core.predecoded_core = false;
    interpreted.translate_blocks = false;
    for (int i = 0; i < repeats; ++i) {
        bench.push_back(run_avrbench(elf, t.cycles, vcd_path, &events));
        bench_interpreted.push_back(run_avrbench(elf, t.cycles, vcd_path, &events, interpreted));
        bench_simavr_core.push_back(run_avrbench(elf, t.cycles, vcd_path, &events, simavr_core));
        bare.push_back(run_bare_simavr(elf, t.cycles));
        if (with_qemu && t.why.empty()) {
            // The kernels run in functions of their own: timed to the PC's
            // arrival at workload_done or the 20 bytes after it (set_sleep_mode,
            // sleep_enable, cli and the SLEEP loop, avr-objdump of workload_1).
            const double s = avrbench_perf::qemu_cpu_seconds(path, *done_addr, *done_addr + 20, t.why, true);
            if (s > 0) emu.push_back(s);
        }
    }
    std::filesystem::remove(vcd_path);
    t.bench = median(bench);
    t.bench_interpreted = median(bench_interpreted);
    t.bench_simavr_core = median(bench_simavr_core);
    t.bare = median(bare);
    if (!emu.empty()) t.qemu = median(emu);
    return t;
}

// --workloads: the suite of firmware/workloads (nine CPU kernels, each to
// its workload_done), every side as --mips runs busy_poll_passes; the
// bench's speed against qemu-system-avr per kernel (qemu CPU / bench CPU:
// above 1 the bench is faster), their geometric mean and the worst kernel.
void run_workloads(const std::string& firmware_dir, int repeats, const std::string& vcd_path) {
    static const char* const kNames[] = {"int_div", "fixed_mul", "soft_float", "memory", "flash_table",
                                         "branches", "calls", "interrupts", "mixed"};
    const std::string qemu = avrbench_perf::qemu_version();
    std::printf("workload suite (firmware/workloads): CPU seconds, median of %d interleaved runs; %s\n", repeats,
                qemu.empty() ? "qemu-system-avr not installed (bash ci/setup --perf)" : qemu.c_str());
    // "interp.": the bench's core without block translation (--no-block-translation).
    std::printf("%-14s %8s %8s %9s %9s %9s %9s %9s %9s %11s\n", "kernel", "M instr", "M cycles", "bench", "interp.",
                "simavr-c", "bare", "qemu", "MIPS", "qemu/bench");
    double log_sum = 0, log_sum_cpu = 0;
    int measured = 0, measured_cpu = 0;
    double worst = 0;
    std::string worst_name;
    for (int k = 1; k <= 9; ++k) {
        const std::string path = firmware_dir + "/workload_" + std::to_string(k) + ".elf";
        const SideTimes t = time_program(path, "workload_done", repeats, vcd_path, !qemu.empty());
        const double ratio = t.qemu > 0 ? t.qemu / t.bench : 0;
        std::printf("%-14s %8.1f %8.1f %9.3f %9.3f %9.3f %9.3f %9.3f %9.1f %11.3f%s\n", kNames[k - 1],
                    static_cast<double>(t.instructions) / 1e6, static_cast<double>(t.cycles) / 1e6, t.bench,
                    t.bench_interpreted, t.bench_simavr_core, t.bare, t.qemu, static_cast<double>(t.instructions) / t.bench / 1e6, ratio,
                    t.qemu > 0 ? "" : (" (" + t.why + ")").c_str());
        if (t.qemu > 0) {
            log_sum += std::log(ratio);
            ++measured;
            // qemu's timers run on its own clock, not per instruction: the
            // interrupt kernel measures that more than its CPU (below apart).
            if (k != 8) log_sum_cpu += std::log(ratio), ++measured_cpu;
            if (worst_name.empty() || ratio < worst) worst = ratio, worst_name = kNames[k - 1];
        }
    }
    if (measured > 0) {
        std::printf("geometric mean qemu/bench %.3f over %d kernels (goal >= 1), without interrupts %.3f over %d; worst kernel "
                    "%s %.3f (goal >= 0.8)\n",
                    std::exp(log_sum / measured), measured, measured_cpu > 0 ? std::exp(log_sum_cpu / measured_cpu) : 0.0,
                    measured_cpu, worst_name.c_str(), worst);
    }
}

void run_mips(const std::string& firmware_dir, int repeats, const std::string& vcd_path) {
    const std::string path = firmware_dir + "/busy_poll_passes.elf";
    const auto elf = avrbench::ElfImage::load(path);
    const auto main_addr = elf.symbol_address("main"), done_addr = elf.symbol_address("busy_poll_done");
    if (!main_addr || !done_addr) {
        std::fprintf(stderr, "avrbench_perf: %s has no main or busy_poll_done\n", path.c_str());
        return;
    }
    // The work: instructions and cycles to the end (the core halts at the SLEEP).
    std::uint64_t instructions = 0;
    avr_cycle_count_t cycles = 0;
    {
        avrbench::Mcu mcu(elf);
        while (mcu.run_until(mcu.cycle() + mcu.frequency_hz()) != avrbench::StopReason::Halted) {
        }
        instructions = mcu.steps();
        cycles = mcu.cycle();
    }
    const std::string qemu = avrbench_perf::qemu_version();
    std::vector<double> bare, bench, bench_simavr_core, emu;
    std::string why;
    std::uint64_t events = 0;
    avrbench::McuOptions simavr_core;
    simavr_core.predecoded_core = false;
    for (int i = 0; i < repeats; ++i) {
        bench.push_back(run_avrbench(elf, cycles, vcd_path, &events));
        bench_simavr_core.push_back(run_avrbench(elf, cycles, vcd_path, &events, simavr_core));
        bare.push_back(run_bare_simavr(elf, cycles));
        if (!qemu.empty() && why.empty()) {
            const double s = avrbench_perf::qemu_cpu_seconds(path, *main_addr, *done_addr, why);
            if (s > 0) emu.push_back(s);
        }
    }
    std::filesystem::remove(vcd_path);
    std::printf("busy_poll_passes: %.1f M AVR instructions, %.1f M cycles (%.2f s at 16 MHz); CPU seconds, median of %d "
                "interleaved runs\n",
                static_cast<double>(instructions) / 1e6, static_cast<double>(cycles) / 1e6, static_cast<double>(cycles) / 16e6,
                repeats);
    std::printf("%-56s %9s %9s %12s\n", "side", "CPU s", "MIPS", "CPU / bench");
    const double b = median(bench);
    const auto row = [&](const std::string& name, double cpu) {
        std::printf("%-56s %9.3f %9.1f %12.3f\n", name.c_str(), cpu, static_cast<double>(instructions) / cpu / 1e6,
                    cpu / b);
    };
    row("avrbench (every pin and USART0 traced, VCD streamed)", b);
    row("avrbench --simavr-core (avr_run_one per instruction)", median(bench_simavr_core));
    row("bare simavr (run_avr's loop)", median(bare));
    if (qemu.empty()) {
        std::printf("%-56s (not installed: bash ci/setup --perf)\n", "qemu-system-avr");
    } else if (emu.empty()) {
        std::printf("%-56s (failed: %s)\n", "qemu-system-avr", why.c_str());
    } else {
        row(qemu + " (TCG, not cycle-exact)", median(emu));
    }
    std::printf("(CPU / bench: the row's CPU time over the bench's; below 1 the row is faster than the bench)\n");
}

// --rss: the CLI's peak memory streaming a VCD of 1 M events per simulated second.
void run_rss_rows(const std::vector<double>& rss_seconds, const std::string& firmware_dir, const std::string& vcd_path) {
    std::printf("%-44s %9s %14s\n", "avrbench run toggle_1mhz --trace-only PB0 --vcd", "sim s", "peak RSS MiB");
    for (const double seconds : rss_seconds) {
        const double mib = cli_peak_rss_mib(firmware_dir + "/toggle_1mhz.elf", seconds, vcd_path);
        std::printf("%-44s %9.0f %14.1f\n", "", seconds, mib);
        std::filesystem::remove(vcd_path);
        std::filesystem::remove(vcd_path.substr(0, vcd_path.size() - 4) + ".gtkw");
    }
}

// The side-by-side table: CPU seconds of alternating runs, median per side.
void run_workload_table(const std::string& firmware_dir, int repeats, double scale, const std::string& vcd_path) {
    std::printf("CPU seconds, median of %d alternating runs per side\n", repeats);
    std::printf("%-48s %7s %11s %11s %9s %9s %7s\n", "workload", "sim s", "bare RTF", "bench RTF", "bare s",
                "bench s", "ratio");
    for (const auto& w : kWorkloads) {
        const auto elf = avrbench::ElfImage::load(firmware_dir + "/" + w.elf + ".elf");
        const double simulated_s = w.simulated_s * scale;
        const auto cycles = static_cast<avr_cycle_count_t>(simulated_s * elf.embedded_frequency_hz());
        std::vector<double> bare, bench;
        std::uint64_t events = 0;
        for (int i = 0; i < repeats; ++i) {
            bare.push_back(run_bare_simavr(elf, cycles));
            bench.push_back(run_avrbench(elf, cycles, vcd_path, &events));
        }
        const double b = median(bare), a = median(bench);
        std::printf("%-48s %7.1f %10.1fx %10.1fx %9.3f %9.3f %7.3f  (%llu trace events)\n", w.name, simulated_s,
                    simulated_s / b, simulated_s / a, b, a, a / b, static_cast<unsigned long long>(events));
    }
    std::filesystem::remove(vcd_path);

}

// The thermal plant's overhead on the same firmware and simulated time.
void run_thermal_overhead(const std::string& firmware_dir, int repeats, double scale) {
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
}

int perf_main(int argc, char** argv) {
    CLI::App app{"avrbench_perf: bench vs bare simavr on the same ELFs"};
    int repeats = 3;
    double scale = 1.0;
    std::string firmware_dir = AVRBENCH_FIRMWARE_DIR;
    app.add_option("--repeats", repeats, "alternating runs per side (the median is kept)");
    app.add_option("--scale", scale, "multiply every workload's simulated time");
    app.add_option("--firmware-dir", firmware_dir, "where the firmware ELFs are");
    bool only_thermal = false;
    app.add_flag("--only-thermal", only_thermal, "only the thermal plant's overhead");
    std::string only_workload, side = "bench";
    app.add_option("--workload", only_workload, "run only this workload (its ELF name), one side, once");
    app.add_option("--side", side, "bare | bench, with --workload")->check(CLI::IsMember({"bare", "bench"}));
    std::string external_elf, external_mcu = "atmega328p";
    double external_seconds = 5.0;
    app.add_option("--elf", external_elf, "only this ELF (built outside the repo), idle, both sides");
    app.add_option("--mcu", external_mcu, "its MCU (default atmega328p; 16 MHz)");
    app.add_option("--seconds", external_seconds, "its simulated time (default 5)");
    std::size_t compare_edges = 0;
    app.add_option("--compare-edges", compare_edges, "only the comparison rules, on this many edges per signal");
    bool only_fast_forward = false;
    app.add_flag("--fast-forward", only_fast_forward, "only idle fast-forward on boards (plain vs skipping, same end, same timeline)");
    bool only_printer = false;
    app.add_flag("--printer", only_printer, "only seed 001's five-MCU printer (lookahead, strict, one MCU, the CLI)");
    bool no_strict = false;
    app.add_flag("--no-strict", no_strict, "with --printer: leave out the strict-lockstep row (about two minutes a run)");
    bool printer_part_once = false;
    app.add_flag("--printer-part-once", printer_part_once, "the printer's part job once, lookahead (for callgrind)");
    bool only_workloads = false;
    app.add_flag("--workloads", only_workloads, "only the workload suite (firmware/workloads): the bench, bare simavr and qemu per kernel");
    bool only_mips = false;
    app.add_flag("--mips", only_mips, "only MIPS on busy_poll_passes: the bench, bare simavr and qemu-system-avr");
    std::size_t check_rss_edges = 0;
    app.add_option("--check-rss", check_rss_edges, "peak RSS of avrbench check and golden update on a run of this many edges");
    std::vector<double> rss_seconds;
    app.add_option("--rss", rss_seconds, "peak RSS of the CLI streaming a 1 M events/s VCD for these simulated seconds");
    CLI11_PARSE(app, argc, argv);
    if (only_fast_forward) {
        run_fast_forward(firmware_dir, AVRBENCH_SOURCE_DIR, repeats, scale);
        return 0;
    }
    if (printer_part_once) {
        run_printer_part_once(firmware_dir, AVRBENCH_SOURCE_DIR);
        return 0;
    }
    if (only_printer) {
        run_printer_lockstep(firmware_dir, AVRBENCH_SOURCE_DIR, repeats, !no_strict);
        return 0;
    }

    const auto vcd_path = (std::filesystem::temp_directory_path() / "avrbench_perf.vcd").string();
    if (!only_workload.empty()) return run_one_side(only_workload, side, firmware_dir, scale, vcd_path);
    if (!external_elf.empty()) {
        run_external_elf(external_elf, external_mcu, external_seconds, repeats, vcd_path);
        return 0;
    }
    if (compare_edges > 0) {
        run_compare_rows(compare_edges);
        return 0;
    }
    if (only_mips) {
        run_mips(firmware_dir, repeats, vcd_path);
        return 0;
    }
    if (only_workloads) {
        run_workloads(firmware_dir, repeats, vcd_path);
        return 0;
    }
    if (check_rss_edges > 0) {
        run_check_rss(check_rss_edges, firmware_dir);
        return 0;
    }
    if (!rss_seconds.empty()) {
        run_rss_rows(rss_seconds, firmware_dir, vcd_path);
        return 0;
    }
    if (!only_thermal) run_workload_table(firmware_dir, repeats, scale, vcd_path);
    run_thermal_overhead(firmware_dir, repeats, scale);
    if (!only_thermal) run_motor_overhead(firmware_dir, AVRBENCH_SOURCE_DIR, repeats, scale);
    if (!only_thermal) run_printer_lockstep(firmware_dir, AVRBENCH_SOURCE_DIR, repeats, true);
    if (!only_thermal) run_fast_forward(firmware_dir, AVRBENCH_SOURCE_DIR, repeats, scale);
    return 0;
}

int main(int argc, char** argv) {
    try {
        return perf_main(argc, argv);
    } catch (const std::exception& e) {
        // A bad ELF or board is one line and exit code 2, as in the CLI.
        std::fprintf(stderr, "avrbench_perf: error: %s\n", e.what());
        return 2;
    }
}
