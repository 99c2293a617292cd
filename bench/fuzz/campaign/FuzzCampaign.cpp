#include "fuzz/campaign/FuzzCampaign.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "core/Units.hpp"
#include "core/UserStop.hpp"
#include "fuzz/FuzzFindings.hpp"
#include "fuzz/campaign/Engines.hpp"
#include "fuzz/campaign/Processes.hpp"
#include "run/Bench.hpp"
#include "stimulus/GcodeMutator.hpp"
#include "stimulus/UartHost.hpp"

namespace avrbench {
namespace fuzz_campaign {
namespace {

namespace fs = std::filesystem;

// Lines the family's firmware answers with ok; the mutator builds on them.
std::vector<std::string> seed_lines(const std::string& family) {
    if (family == "grbl") return {"G21 G91\nG1 X1 Y1 F500\n", "$$\n", "G0 X2\nG4 P0.1\n", "?"};
    if (family == "marlin" || family == "teacup") return {"G1 X1 Y1 F500\n", "G01 X0.5 Y0 F10\n", "M105\n", "M114\n", "G92 X0 Y0\n"};
    return {"G1 X1 F500\n", "\n"};
}

// Which ELF runs where: the fuzzed one on the MCU of the board's serial
// port, the others from --firmware; and the port's firmware family.
struct FuzzFirmware {
    std::string family;
    std::string other_firmware;             // "mcu=elf;mcu=elf" for the target
    std::vector<std::string> run_firmware;  // `run ELF --firmware ...` as the recorded runs give it
};

FuzzFirmware fuzz_firmware(const FuzzCampaignOptions& args) {
    FuzzFirmware fw;
    // BadInput for a bad board or ELF, as `run` says it.
    BoardSpec spec = load_board_file(args.board);
    if (spec.serial_port_mcu().empty()) throw BadInput(args.board + ": has no serial port (a serial_host part) for the fuzz input");
    std::map<std::string, std::string> firmware = args.firmware;
    for (const auto& [mcu, elf] : firmware) fw.other_firmware += (fw.other_firmware.empty() ? "" : ";") + mcu + "=" + elf;
    firmware[spec.serial_port_mcu()] = args.elf;
    // run's ELF goes to the board's first MCU, which need not be the serial port's.
    const std::string first_mcu = spec.mcus.front().name;
    fw.run_firmware.push_back(firmware.count(first_mcu) != 0 ? firmware[first_mcu] : args.elf);
    for (const auto& [mcu, elf] : firmware) {
        if (mcu != first_mcu) fw.run_firmware.insert(fw.run_firmware.end(), {"--firmware", mcu + "=" + elf});
    }
    Bench bench(std::move(spec), firmware);
    fw.family = args.family.empty() ? bench.serial_port().protocol().family : args.family;
    (void)parse_firmware_family(fw.family, "--family");
    return fw;
}

// What the reproducers' runs need besides the campaign.
struct FindingsRun {
    const FuzzCampaignOptions& args;
    const std::vector<std::string>& run_firmware;
    const std::string& family;
    const fs::path& findings;
    double bound_s;
    // Minimisation stops here (a campaign bounded by --for alone); none
    // with --runs, where the replays' count bounds it.
    std::optional<std::chrono::steady_clock::time_point> deadline;
    fs::path hits;  // the target's count of inputs per root cause ("": none)
    // When the engine started, on the clock of file times: a reproducer's
    // write time less this is when the engine found it.
    fs::file_time_type engine_started;
};

// The target's <seen>.hits: one line per input that hit a root cause.
std::map<std::string, std::size_t> hits_per_cause(const fs::path& hits) {
    std::map<std::string, std::size_t> count;
    std::ifstream in(hits);
    for (std::string line; std::getline(in, line);) ++count[line];
    return count;
}

// Replays each reproducer once (the target prints the finding and aborts),
// groups them, minimizes the shortest of each group and records its run.
// Exit code: 1 when something was found.
int report_findings(Campaign& campaign, const std::vector<std::string>& env, const FindingsRun& how) {
    const FuzzCampaignOptions& args = how.args;
    const auto& run_firmware = how.run_firmware;
    const std::string& family = how.family;
    const fs::path& findings = how.findings;
    const double bound_s = how.bound_s;
    const Target& target = campaign.target;
    if (user_stop_requested()) {
        // Stopped (Ctrl-C, SIGTERM): what the engine kept stays for a later
        // look; nothing is replayed, so the stop is honoured at once.
        std::printf("  interrupted: %zu reproducers kept in %s, not replayed (replay one with --replay FILE)\n",
                    campaign.artifacts.size(), campaign.artifact_dir.c_str());
        return 130;
    }
    std::map<std::string, std::vector<fs::path>> by_cause;
    std::map<std::string, std::string> example;  // root cause -> the first replay's whole line
    std::size_t not_reproduced = 0;
    std::vector<fs::path>& artifacts = campaign.artifacts;
    std::sort(artifacts.begin(), artifacts.end());
    for (const auto& artifact : artifacts) {
        const std::string line = replay(target, env, artifact);
        if (line.empty()) {
            ++not_reproduced;  // e.g. libFuzzer's own crash report of a job, or a flaky bench: kept, not listed
            continue;
        }
        const std::string cause = finding_root_cause(line);
        by_cause[cause].push_back(artifact);
        example.emplace(cause, line.substr(line.find("instructions: ") + 14));
    }
    const auto hits = how.hits.empty() ? std::map<std::string, std::size_t>{} : hits_per_cause(how.hits);
    std::printf("  findings   %zu distinct root causes (%zu reproducers in %s", by_cause.size(), artifacts.size(),
                campaign.artifact_dir.c_str());
    if (not_reproduced != 0) std::printf("; %zu did not reproduce on replay", not_reproduced);
    std::printf(")\n");
    int index = 0;
    for (auto& [cause, files] : by_cause) {
        // The shortest reproducer of each, minimized (the same root cause
        // must remain), recorded as a run with its VCD.
        const fs::path shortest = *std::min_element(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
            return fs::file_size(a) < fs::file_size(b);
        });
        const std::string base = (findings / ("finding-" + std::to_string(++index))).string();
        const bool out_of_time = how.deadline && std::chrono::steady_clock::now() >= *how.deadline;
        const std::string minimal = minimize(target, env, base + ".try", slurp(shortest.string()), cause, how.deadline);
        std::ofstream(base + ".gcode", std::ios::binary) << minimal;
        // Replayed the way the fuzz target sent it: lines through the port's
        // host, bytes that are not text included.
        std::vector<std::string> run = {self_dir() + "/avrbench", "run"};
        run.insert(run.end(), run_firmware.begin(), run_firmware.end());
        run.insert(run.end(), {"--board", args.board, "--for", std::to_string(bound_s + 1) + "s", "--vcd", base + ".vcd"});
        if (args.raw) {
            // The bytes from power-on (the fuzz target sent them after its boot time; --uart-in holds
            // them until the firmware enables its receiver).
            run.insert(run.end(), {"--uart-in", base + ".gcode"});
        } else {
            // A generic firmware got it after its first line or --boot, as the target sent it.
            run.insert(run.end(), {"--family", family, "--gcode", base + ".gcode", "--gcode-bytes", "--generic-boot", args.boot});
        }
        run_logged(run, {}, base + ".txt");
        const auto hit = hits.find(cause);
        const std::size_t inputs = hit != hits.end() ? hit->second : files.size();
        // The first reproducer the engine wrote for this root cause.
        fs::file_time_type first = fs::file_time_type::max();
        for (const auto& f : files) {
            std::error_code ec;
            const auto t = fs::last_write_time(f, ec);
            if (!ec) first = std::min(first, t);
        }
        const double first_s = first == fs::file_time_type::max()
                                   ? -1.0
                                   : std::max(0.0, std::chrono::duration<double>(first - how.engine_started).count());
        std::printf("    %d. %s (%zu input%s hit it; first found %.1f s into the fuzzing)\n       e.g. %s\n       %s: %zu bytes (from %ju), %s.gcode; its run: %s.txt, %s.vcd\n",
                    index, cause.c_str(), inputs, inputs == 1 ? "" : "s", first_s, example[cause].c_str(),
                    out_of_time ? "not minimized (the --for budget was spent)" : "minimized", minimal.size(),
                    static_cast<std::uintmax_t>(fs::file_size(shortest)), base.c_str(), base.c_str(), base.c_str());
    }
    return by_cause.empty() ? 0 : 1;
}

}  // namespace
}  // namespace fuzz_campaign

using namespace fuzz_campaign;
namespace fs = std::filesystem;

BoardRunOptions fuzz_replay_run(const FuzzCampaignOptions& args, const std::string& input) {
    const FuzzFirmware fw = fuzz_firmware(args);
    const double bound_s = seconds_from_ps(parse_duration_ps(args.bound, "--bound"));
    BoardRunOptions o;
    o.board = args.board;
    o.elf = fw.run_firmware.front();
    for (std::size_t i = 1; i + 1 < fw.run_firmware.size(); i += 2) {
        const std::string& item = fw.run_firmware[i + 1];
        o.firmware[item.substr(0, item.find('='))] = item.substr(item.find('=') + 1);
    }
    o.duration_ps = ps_from_seconds(bound_s + 1, "--bound");
    o.read_uart_input = [](const std::string& path) { return read_input_file(path, "--replay", kMaxUartInputBytes); };
    if (args.raw) {
        o.uart_in.push_back({"", input});
    } else {
        BoardRunOptions::GcodeJob job;
        job.path = input;
        job.raw_bytes = true;
        job.family = fw.family;
        job.generic_boot_s = seconds_from_ps(parse_duration_ps(args.boot, "--boot"));
        o.gcode = job;
    }
    o.on_announce = [](const std::string& line) { std::printf("%s\n", line.c_str()); };
    return o;
}

int run_fuzz_campaign(const FuzzCampaignOptions& args) {
    const double seconds = seconds_from_ps(parse_duration_ps(args.duration, "--for"));
    const double bound_s = seconds_from_ps(parse_duration_ps(args.bound, "--bound"));
    if (seconds < 1) throw BadInput("--for: fuzz for at least 1s");
    const FuzzFirmware fw = fuzz_firmware(args);
    const std::string& family = fw.family;
    const std::vector<std::string>& run_firmware = fw.run_firmware;
    const std::string& other_firmware = fw.other_firmware;
    const fs::path out = args.out;
    const fs::path corpus = out / "corpus", findings = out / "findings";
    {
        std::error_code ec;
        fs::create_directories(corpus, ec);
        if (!ec) fs::create_directories(findings, ec);
        if (ec) throw BadInput("--out: cannot make " + corpus.string() + " and " + findings.string() + ": " + ec.message());
    }
    // Raw: a few bytes of seed 002's record protocol (M30, a G00 header);
    // coverage finds the rest.
    const std::vector<std::string> seeds =
        args.raw ? std::vector<std::string>{std::string("\x3b", 1), std::string("\x00\x00\x10\x00\x10\x40\x40\x05", 8)}
                 : seed_lines(family);
    for (std::size_t i = 0; i < seeds.size(); ++i) std::ofstream(corpus / ("seed-" + std::to_string(i))) << seeds[i];
    if (!args.corpus.empty()) {
        std::error_code ec;
        if (!fs::is_directory(args.corpus, ec)) throw BadInput(args.corpus + ": --corpus is not a directory");
        std::size_t copied = 0;
        for (const auto& entry : fs::directory_iterator(args.corpus, ec)) {
            // A link that loops or leads nowhere is skipped; files are copied.
            std::error_code file_ec;
            if (!entry.is_regular_file(file_ec) || file_ec) continue;
            fs::copy_file(entry.path(), corpus / ("user-" + entry.path().filename().string()), fs::copy_options::overwrite_existing,
                          file_ec);
            if (file_ec) throw BadInput("--corpus: " + entry.path().string() + ": cannot copy (" + file_ec.message() + ")");
            ++copied;
        }
        if (ec) throw BadInput("--corpus: " + args.corpus + ": cannot read (" + ec.message() + ")");
        if (copied == 0) throw BadInput(args.corpus + ": --corpus holds no files");
    }
    {
        std::ofstream dict(out / "gcode.dict");
        for (const auto& word : gcode_dictionary()) dict << '"' << word << "\"\n";  // libFuzzer's and AFL's format
    }
    std::vector<std::string> env = {"AVRBENCH_FUZZ_BOARD=" + args.board, "AVRBENCH_FUZZ_ELF=" + args.elf,
                                          "AVRBENCH_FUZZ_BOUND=" + std::to_string(bound_s), "AVRBENCH_FUZZ_FAMILY=" + family,
                                          std::string("AVRBENCH_FUZZ_RAW=") + (args.raw ? "1" : "0"),
                                          "AVRBENCH_FUZZ_BOOT=" + std::to_string(seconds_from_ps(parse_duration_ps(args.boot, "--boot"))),
                                          "AVRBENCH_FUZZ_FIRMWARE=" + other_firmware,
                                          std::string("AVRBENCH_FUZZ_HANG=") + (args.hang ? "1" : "0"),
                                          "AVRBENCH_FUZZ_STEADY=" + std::to_string(args.steady)};
    const auto started = std::chrono::steady_clock::now();
    // --for bounds the whole campaign: the engine gets four fifths of it and
    // the replays, minimisation and recorded runs the rest, stopping at the
    // end. With --runs the executions bound the engine, and each root
    // cause's minimisation takes at most kMinimizeReplays replays, on any
    // machine the same.
    std::optional<std::chrono::steady_clock::time_point> deadline;
    double engine_s = seconds;
    if (args.runs == 0) {
        engine_s = std::max(1.0, seconds * 0.8);
        deadline = started + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
        std::printf("avrbench fuzz: %.0f s in all: fuzzing %.0f s, then replaying and minimising what it found until the end\n",
                    seconds, engine_s);
    } else {
        std::printf("avrbench fuzz: minimising takes at most %d replays per root cause after the %lu executions\n",
                    kMinimizeReplays, args.runs);
    }
    const fs::file_time_type engine_started = fs::file_time_type::clock::now();
    Campaign campaign = args.engine == "afl" ? afl_campaign(args, env, out, corpus, engine_s, bound_s, family)
                                             : libfuzzer_campaign(args, env, out, corpus, findings, engine_s, family);
    const double campaign_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::printf("  executions %lu in %.1f s (%.0f per second)\n", campaign.executions, campaign_s,
                campaign_s > 0 ? static_cast<double>(campaign.executions) / campaign_s : 0.0);
    std::printf("  coverage   firmware edge %s %lu at the start, %lu at the end\n",
                campaign.target.libfuzzer ? "features" : "tuples (AFL++'s edges)", campaign.coverage_start,
                campaign.coverage_end);
    if (campaign.inputs_counted != 0) {
        std::printf("  repeating  %lu of %lu inputs ended before their bound, only repeating themselves (stepping, no new "
                    "coverage for --steady %llu instructions, no part able to find more at that pace)\n",
                    campaign.ended_steady, campaign.inputs_counted, static_cast<unsigned long long>(args.steady));
    }
    if (campaign.wall_timeouts != 0) {
        std::printf("  timeouts   %lu inputs ran past AFL++'s wall-clock limit (out/afl/*/hangs; not findings: "
                    "the simulated bound is the hang oracle)\n",
                    campaign.wall_timeouts);
    }

    const fs::path hits = args.engine == "afl" ? fs::path() : out / "seen-findings.txt.hits";
    return report_findings(campaign, env, FindingsRun{args, run_firmware, family, findings, bound_s, deadline, hits, engine_started});
}

}  // namespace avrbench
