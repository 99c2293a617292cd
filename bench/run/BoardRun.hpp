// One run of a board, the way every front end runs one: the board prepared
// from a file and firmware, jobs and bytes on its serial ports, a pty bridge,
// what is traced, the VCD streamed as the run goes (bounded memory), the
// HTML report and the port captures written at the end, progress reported
// after each slice, the end-of-run summary and the verdict. The CLI's
// `run --board` parses arguments into BoardRunOptions and prints what this
// returns; the C++ API, a debugger or a binding do the same.
#pragma once

#include <chrono>
#include <functional>
#include <atomic>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/OutputFile.hpp"
#include "core/Time.hpp"
#include "trace/Recorder.hpp"
#include "trace/VcdWriter.hpp"
#include "run/Bench.hpp"

namespace avrbench {

class PtyBridge;
class RecordHost;

struct BoardRunOptions {
    std::string board;                            // a board file or a standard board's name
    std::string elf;                              // the firmware of the board's first MCU
    std::map<std::string, std::string> firmware;  // MCU name -> ELF for the board's other MCUs
    Picoseconds duration_ps = kPsPerMs * 1000;    // the run's limit (with a job: for finishing it)
    Picoseconds settle_ps = 50 * kPsPerMs;        // a job is done once motion and lines were quiet this long
    bool skip_idle_loops = true;                  // mcu/IdleLoopSkip.hpp
    bool predecoded_core = true;                  // mcu/PredecodedCore.hpp; false: simavr's avr_run_one
    bool translate_blocks = true;                 // mcu/BlockTranslator.hpp (on the predecoded core)
    bool periodic_waves = true;                   // periph/timer/PeriodicOutput.hpp

    // Serial ports by name ("" = the board's first).
    struct PortBytes {
        std::string port;
        std::string path;  // --uart-in: read after every file is checked
    };
    std::vector<PortBytes> uart_in;   // sent to the firmware at power-on
    std::vector<PortBytes> uart_out;  // what the firmware sent, written at the end
    // How uart_in paths are read (the CLI's reads "-" as standard input).
    std::function<std::string(const std::string& path)> read_uart_input;

    // A G-code job streamed by a UartHost on `port`.
    struct GcodeJob {
        std::string path;
        bool raw_bytes = false;  // the file's bytes as lines, binary bytes included (fuzz reproducers)
        std::string flow, family, line_timeout;  // overrides of the port's declaration ("" = the board's)
        std::vector<std::string> error_patterns;  // besides the family's and the board's
        bool wait_banner = false;
        // A generic firmware's port that starts at once: after its first
        // output line instead, at most this long (start_generic_after_boot:
        // the fuzz target's boot, for replaying its reproducers).
        std::optional<double> generic_boot_s;
        std::vector<std::pair<Picoseconds, std::string>> realtime;  // bytes sent outside the line stream
    };
    std::optional<GcodeJob> gcode;
    // A job of binary records (seed 002's plotter protocol) acknowledged one by one.
    struct RecordJob {
        std::string source;  // what the records came from, for the summary
        std::string variant;  // "faithful" / "improved", for the summary
        std::vector<std::string> messages;
        std::vector<double> busy_seconds;
        // The G-code the records were made from: the path the board's
        // motion judges hold the machine to ("" for none).
        std::string gcode;
    };
    // Made once the board's files are checked and the board is built (the
    // CLI reads a drawing through the CAM then); empty = no such job.
    std::function<RecordJob()> records;
    std::string job_port;  // the port of gcode or records ("" = the first)

    // A port bridged to a pseudo-terminal a host program opens.
    struct Pty {
        std::string port, link;
        bool realtime_pace = false;  // simulated time no further than wall time
        bool reset_on_open = false;  // a host opening the port resets its MCU (an Arduino's DTR)
    };
    std::optional<Pty> pty;

    // What is recorded and written (paths "" = not written).
    std::string vcd;
    VcdOptions vcd_layout;
    std::string report;
    std::string trace;       // pins added to the board's defaults (MCU.PIN or PIN lists)
    std::string trace_only;  // pins recorded instead of the defaults
    // The timing profile of every MCU (mcu/TimingProfile.hpp), written
    // here as JSON and shown in the summary; "" = not collected.
    std::string profile;
    // Files the caller reads or writes besides these (checked with them: each
    // output a file of its own, none an input).
    RunFiles more_files;

    // After every slice: the fraction of duration_ps done and the simulated seconds.
    std::function<void(double fraction, double simulated_s)> on_progress;
    // A status line (run/LiveStatus.hpp) every status_every_ps of simulated
    // time (0: none), and when *status_now is set (a signal handler's flag);
    // each also rewrites status_file ("" = none) with the JSON, whole.
    Picoseconds status_every_ps = 0;
    std::atomic<bool>* status_now = nullptr;
    std::string status_file;
    std::function<void(const std::string& line)> on_status;
    // Lines to show at once while the run goes on (the pty's path).
    std::function<void(const std::string& line)> on_announce;
};

// How a run ended, for a front end's exit code (docs/CLI.md).
struct RunVerdict {
    enum class Outcome { Ok, Finding, Timeout, Interrupted };
    Outcome outcome = Outcome::Ok;
    std::string message;  // one line for stderr ("" when Ok or for a finding)
};

class BoardRun {
public:
    // Loads the board and checks everything before anything runs (BadInput,
    // one line naming what and where).
    explicit BoardRun(BoardRunOptions options);
    ~BoardRun();
    BoardRun(const BoardRun&) = delete;
    BoardRun& operator=(const BoardRun&) = delete;

    // Runs to the limit (or the job's end), then writes the VCD, its save
    // file, the report and the port captures.
    IdleResult run();

    // The verdict: part, net and host findings count only when `strict`.
    RunVerdict verdict(bool strict) const;
    // The end-of-run summary, one line per entry ("avrbench run: board ...").
    std::vector<std::string> summary() const;

    Bench& bench() { return *bench_; }
    const std::vector<Finding>& findings() const { return findings_; }
    UartHost* host() const { return host_; }
    double wall_seconds() const { return wall_s_; }

private:
    void check_files(const BoardSpec& spec);
    void start_gcode_job();
    void start_record_job();
    void open_pty();
    void count_i2c();
    void trace();
    void after_slice(std::chrono::steady_clock::time_point wall_start);

    BoardRunOptions options_;
    std::unique_ptr<Bench> bench_;
    UartHost* host_ = nullptr;
    std::unique_ptr<RecordHost> plot_;
    std::string plot_source_, plot_variant_;
    std::unique_ptr<PtyBridge> pty_;
    Mcu* pty_mcu_ = nullptr;
    unsigned resets_on_open_ = 0;
    Picoseconds next_status_ps_ = 0;
    void report_status(std::chrono::steady_clock::time_point wall_start);
    struct I2cCount {
        std::uint64_t transfers = 0, bytes = 0, nacks = 0;
    };
    std::map<std::string, std::shared_ptr<I2cCount>> i2c_;  // per master MCU
    std::function<void(Picoseconds)> drain_;                // the VCD stream, during run()
    IdleResult outcome_ = IdleResult::TimeLimit;
    std::vector<Finding> findings_;
    std::string gtkw_path_;
    double wall_s_ = 0;
};

// Recorder::trace_pins, its error named after the option that gave the list.
void trace_pins_option(Recorder& recorder, Mcu& mcu, const std::string& spec, const char* option);


}  // namespace avrbench
