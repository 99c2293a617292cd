// Seed 001's five-MCU printer (bench/boards/printer3d-seed001.yaml): the
// demo part's job (examples/printer3d/seed001_part.gcode) run to the end
// (a) with the lockstep's lookahead, as the CLI runs it, (b) in strict
// lockstep (every core within one instruction of every other), and (c) the
// interpolator alone on a bare ATmega2560 (no drive boards, no heater, no
// parts) running the same job without its G28, for what one MCU costs.
// Best CPU time of --repeats alternating runs; real-time factor =
// simulated / CPU seconds.
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>

#include "boards/Board.hpp"
#include "verify/Bench.hpp"

namespace {

double cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

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
    double cpu_s = 0, simulated_s = 0;
};

Sample run_printer(const std::string& fw, const std::string& src, bool lookahead) {
    const double start = cpu_seconds();
    avrbench::Bench bench(src + "/bench/boards/printer3d-seed001.yaml",
                          {{"interp", fw + "/printer3d_interp.elf"},
                           {"drive_x", fw + "/printer3d_drive.elf"},
                           {"drive_y", fw + "/printer3d_drive.elf"},
                           {"drive_z", fw + "/printer3d_drive.elf"},
                           {"drive_e", fw + "/printer3d_drive.elf"},
                           {"heater", fw + "/printer3d_heater.elf"}});
    bench.board().lockstep().set_lookahead(lookahead);
    bench.host().add_lines(read_job(src + "/examples/printer3d/seed001_part.gcode", false));
    bench.run_until_idle(60.0);
    return {cpu_seconds() - start, bench.now_seconds()};
}

constexpr const char* kBareMega = R"(
board: bare-mega
mcus:
  interp: {type: atmega2560, clock: 16MHz}
serial:
  host: {mcu: interp, usart: 0, flow: send_and_wait, family: marlin}
)";

Sample run_interp_alone(const std::string& fw, const std::string& src) {
    const double start = cpu_seconds();
    avrbench::Bench bench(avrbench::parse_board_text(kBareMega, "bare-mega.yaml"),
                          {{"interp", fw + "/printer3d_interp.elf"}});
    bench.host().add_lines(read_job(src + "/examples/printer3d/seed001_part.gcode", true));
    bench.run_until_idle(60.0);
    return {cpu_seconds() - start, bench.now_seconds()};
}

}  // namespace

void run_printer_lockstep(const std::string& firmware_dir, const std::string& source_dir, int repeats) {
    std::printf("\n%-52s %9s %9s %9s\n", "seed 001 printer, demo part (best of runs)", "sim s", "CPU s", "RTF");
    Sample best[3];
    for (auto& b : best) b.cpu_s = 1e300;
    for (int r = 0; r < std::max(1, repeats); ++r) {
        const Sample s[3] = {run_printer(firmware_dir, source_dir, true), run_printer(firmware_dir, source_dir, false),
                             run_interp_alone(firmware_dir, source_dir)};
        for (int k = 0; k < 3; ++k) {
            if (s[k].cpu_s < best[k].cpu_s) best[k] = s[k];
        }
    }
    const char* names[3] = {"(a) five MCUs, lockstep with lookahead", "(b) five MCUs, strict lockstep",
                            "(c) interpolator alone (no G28)"};
    for (int k = 0; k < 3; ++k) {
        std::printf("%-52s %9.3f %9.3f %8.2fx\n", names[k], best[k].simulated_s, best[k].cpu_s,
                    best[k].simulated_s / best[k].cpu_s);
    }
    const double rtf_a = best[0].simulated_s / best[0].cpu_s, rtf_b = best[1].simulated_s / best[1].cpu_s,
                 rtf_c = best[2].simulated_s / best[2].cpu_s;
    std::printf("lookahead speed-up (a)/(b) %.1fx; board cost over one MCU alone (c)/(a) %.2f\n", rtf_a / rtf_b,
                rtf_c / rtf_a);
}
