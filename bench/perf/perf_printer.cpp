// Seed 001's five-MCU printer (bench/boards/printer3d-seed001.yaml):
// (a) the demo's job (examples/printer3d/heat_up.gcode, M109 S200 through the
//     heater MCU, then seed001_part.gcode), as `bash ci/demo` runs it but
//     without writing anything, with the lockstep's lookahead;
// (b) the part's job alone with the lookahead and (c) in strict lockstep
//     (every core within one instruction of every other), for the speed-up;
// (d) the interpolator alone on a bare ATmega2560 (no drive boards, heater or
//     parts) running the part's job without its G28, for what one MCU costs;
// (e) the CLI on the demo's job with --vcd, (f) with --vcd --report, each a
//     child process: its CPU time (user + system) and peak resident memory.
// Best CPU time of --repeats alternating runs; real-time factor = simulated /
// CPU seconds. "Steps" are the MCUs' avr_run() steps (instructions, plus one
// per sleep fast-forward), so "ns/step" is the whole board's cost per
// instruction executed. `--printer-part-once` runs (b) once, for callgrind
// (bench/perf/instructions).
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "CpuTime.hpp"
#include "boards/Board.hpp"
#include "run/Bench.hpp"

namespace {

using avrbench_perf::thread_cpu_seconds;

std::string read_job(const std::string& path, bool drop_homing) {
    std::ifstream in(path);
    std::string line, out;
    while (std::getline(in, line)) {
        if (drop_homing && line.rfind("G28", 0) == 0) continue;
        out += line + "\n";
    }
    return out;
}

struct Sample {
    double cpu_s = 1e300, simulated_s = 0, rss_mib = 0;
    std::uint64_t avr_instructions = 0;
};

// What a run cost since `start_cpu_s`, how far it went, and its MCUs' steps.
Sample sample_of(avrbench::Bench& bench, double start_cpu_s) {
    Sample s;
    s.cpu_s = thread_cpu_seconds() - start_cpu_s;
    s.simulated_s = bench.now_seconds();
    for (const avrbench::Mcu* m : bench.board().mcus()) s.avr_instructions += m->steps();
    return s;
}

enum class Job { Demo, Part };

std::string job_text(const std::string& src, Job job) {
    const std::string part = read_job(src + "/examples/printer3d/seed001_part.gcode", false);
    return job == Job::Demo ? read_job(src + "/examples/printer3d/heat_up.gcode", false) + part : part;
}

Sample run_printer(const std::string& fw, const std::string& src, Job job, bool lookahead) {
    const double start = thread_cpu_seconds();
    avrbench::Bench bench(src + "/bench/boards/printer3d-seed001.yaml",
                          {{"interp", fw + "/printer3d_interp.elf"},
                           {"drive_x", fw + "/printer3d_drive.elf"},
                           {"drive_y", fw + "/printer3d_drive.elf"},
                           {"drive_z", fw + "/printer3d_drive.elf"},
                           {"drive_e", fw + "/printer3d_drive.elf"},
                           {"heater", fw + "/printer3d_heater.elf"}});
    bench.board().lockstep().set_lookahead(lookahead);
    bench.host().add_lines(job_text(src, job));
    bench.run_until_idle(200.0);
    return sample_of(bench, start);
}

constexpr const char* kBareMega = R"(
board: bare-mega
mcus:
  interp: {type: atmega2560, clock: 16MHz}
parts:
  host: {type: serial_host, family: marlin, flow: send_and_wait}
nets:
  host_rx: [interp.PE1, host.rx]
  host_tx: [host.tx, interp.PE0]
)";

Sample run_interp_alone(const std::string& fw, const std::string& src) {
    const double start = thread_cpu_seconds();
    avrbench::Bench bench(avrbench::parse_board_text(kBareMega, "bare-mega.yaml"),
                          {{"interp", fw + "/printer3d_interp.elf"}});
    bench.host().add_lines(read_job(src + "/examples/printer3d/seed001_part.gcode", true));
    bench.run_until_idle(60.0);
    return sample_of(bench, start);
}

// `avrbench run` on the demo's job as `bash ci/demo` runs it, in a child.
Sample run_cli_demo(const std::string& fw, const std::string& src, bool report) {
    const auto dir = std::filesystem::temp_directory_path();
    const std::string job = (dir / "avrbench_perf_demo.gcode").string();
    const std::string vcd = (dir / "avrbench_perf_demo.vcd").string();
    const std::string html = (dir / "avrbench_perf_demo.html").string();
    std::ofstream(job) << job_text(src, Job::Demo);
    const std::string interp = fw + "/printer3d_interp.elf", board = src + "/bench/boards/printer3d-seed001.yaml",
                      x = "drive_x=" + fw + "/printer3d_drive.elf", y = "drive_y=" + fw + "/printer3d_drive.elf",
                      z = "drive_z=" + fw + "/printer3d_drive.elf", e = "drive_e=" + fw + "/printer3d_drive.elf",
                      heater = "heater=" + fw + "/printer3d_heater.elf";
    const pid_t pid = fork();
    if (pid == 0) {
        const int null_fd = open("/dev/null", O_WRONLY);
        dup2(null_fd, STDOUT_FILENO);
        if (report) {
            execl(AVRBENCH_CLI, AVRBENCH_CLI, "run", "-q", interp.c_str(), "--board", board.c_str(), "--firmware", x.c_str(),
                  "--firmware", y.c_str(), "--firmware", z.c_str(), "--firmware", e.c_str(), "--firmware", heater.c_str(),
                  "--gcode", job.c_str(), "--for", "200s", "--vcd", vcd.c_str(), "--report", html.c_str(),
                  static_cast<char*>(nullptr));
        } else {
            execl(AVRBENCH_CLI, AVRBENCH_CLI, "run", "-q", interp.c_str(), "--board", board.c_str(), "--firmware", x.c_str(),
                  "--firmware", y.c_str(), "--firmware", z.c_str(), "--firmware", e.c_str(), "--firmware", heater.c_str(),
                  "--gcode", job.c_str(), "--for", "200s", "--vcd", vcd.c_str(), static_cast<char*>(nullptr));
        }
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    Sample s;
    if (wait4(pid, &status, 0, &usage) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        const auto secs = [](const timeval& t) { return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6; };
        s.cpu_s = secs(usage.ru_utime) + secs(usage.ru_stime);
        s.rss_mib = static_cast<double>(usage.ru_maxrss) / 1024.0;  // KiB on Linux
        s.simulated_s = 104.709;  // the demo job's end (the same run as (a): the CLI prints it)
    }
    for (const auto& f : {job, vcd, html, (dir / "avrbench_perf_demo.gtkw").string()}) std::filesystem::remove(f);
    return s;
}

void keep_best(Sample& best, const Sample& s) {
    if (s.cpu_s < best.cpu_s) best = s;
}

}  // namespace

// Once, for callgrind: the part's job with the lookahead; prints the MCUs'
// steps so that bench/perf/instructions can divide by them.
__attribute__((noinline)) void run_printer_part_once(const std::string& firmware_dir, const std::string& source_dir) {
    const Sample s = run_printer(firmware_dir, source_dir, Job::Part, true);
    std::printf("avr_steps %llu simulated_s %.3f\n", static_cast<unsigned long long>(s.avr_instructions), s.simulated_s);
}

void run_printer_lockstep(const std::string& firmware_dir, const std::string& source_dir, int repeats, bool strict_row) {
    constexpr int kRows = 6;
    Sample best[kRows];
    // Every run's real-time factor of the demo job, in order: on a shared
    // machine the spread says as much as the best.
    std::vector<double> demo_rtf;
    for (int r = 0; r < std::max(1, repeats); ++r) {
        const Sample demo = run_printer(firmware_dir, source_dir, Job::Demo, true);
        demo_rtf.push_back(demo.simulated_s / demo.cpu_s);
        keep_best(best[0], demo);
        keep_best(best[1], run_printer(firmware_dir, source_dir, Job::Part, true));
        if (strict_row) keep_best(best[2], run_printer(firmware_dir, source_dir, Job::Part, false));
        keep_best(best[3], run_interp_alone(firmware_dir, source_dir));
        keep_best(best[4], run_cli_demo(firmware_dir, source_dir, false));
        keep_best(best[5], run_cli_demo(firmware_dir, source_dir, true));
    }
    const char* names[kRows] = {"(a) demo job (M109 + part), lookahead",      "(b) part job, lookahead",
                                "(c) part job, strict lockstep",               "(d) interpolator alone (part, no G28)",
                                "(e) CLI, demo job, --vcd",                    "(f) CLI, demo job, --vcd --report"};
    std::printf("\n%-44s %9s %9s %8s %9s %9s %9s\n", "seed 001 printer (best of runs)", "sim s", "CPU s", "RTF",
                "M steps", "ns/step", "peak MiB");
    for (int k = 0; k < kRows; ++k) {
        const Sample& s = best[k];
        if (k == 2 && !strict_row) continue;
        char insn[32] = "-", per[32] = "-", rss[32] = "-";
        if (s.avr_instructions > 0) {
            std::snprintf(insn, sizeof insn, "%.1f", static_cast<double>(s.avr_instructions) * 1e-6);
            std::snprintf(per, sizeof per, "%.0f", s.cpu_s * 1e9 / static_cast<double>(s.avr_instructions));
        }
        if (s.rss_mib > 0) std::snprintf(rss, sizeof rss, "%.1f", s.rss_mib);
        std::printf("%-44s %9.3f %9.3f %7.2fx %9s %9s %9s\n", names[k], s.simulated_s, s.cpu_s, s.simulated_s / s.cpu_s,
                    insn, per, rss);
    }
    std::printf("(a) every run, in order:");
    for (const double rtf : demo_rtf) std::printf(" %.2fx", rtf);
    std::printf("\n");
    const double rtf_b = best[1].simulated_s / best[1].cpu_s, rtf_d = best[3].simulated_s / best[3].cpu_s;
    if (strict_row) std::printf("lookahead speed-up (b)/(c) %.1fx; ", rtf_b / (best[2].simulated_s / best[2].cpu_s));
    std::printf("board cost over one MCU alone (d)/(b) %.2f\n", rtf_d / rtf_b);
}
