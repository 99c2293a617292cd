// The bench as one object: a board with its firmware, UART hosts on its
// serial ports, a recorder, and the run that waits for a job to finish. The
// CLI and the scenario runner are thin layers over this; tests use it
// directly:
//
//   Bench bench{"bench/boards/arduino-uno-cnc-shield-v3.yaml", "grbl.elf"};
//   bench.host().load_file("job.gcode");
//   bench.run_until_idle(10.0);
//   EXPECT_EQ(bench.axis("x").steps(), 1600u);
#pragma once

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "parts/Axis.hpp"
#include "parts/HostConnector.hpp"
#include "stimulus/UartHost.hpp"
#include "trace/Recorder.hpp"
#include "trace/ReportOfRun.hpp"
#include "trace/RunReport.hpp"
#include "trace/Timeline.hpp"

namespace avrbench {

class CommandedMoves;
class HeatTargets;

enum class IdleResult {
    Idle,        // the firmware is done: Bench::still_going says nothing
    TimeLimit,   // the simulated-time limit came first
    Halted,      // every MCU halted (crash findings say why)
    HostFailed,  // a host stopped: no answer (timeout), ALARM, !!, ...
    Interrupted, // SIGINT/SIGTERM (core/UserStop.hpp)
    RecorderFull,  // the timeline's cap was hit: the run can no longer be recorded whole, so it ends
};

// "idle", "time-limit", "halted", "host-failed", "interrupted", "recorder-full".
const char* to_string(IdleResult result);


// A serial port of the board: a part where a host attaches
// (parts/HostConnector.hpp: a serial_host on the firmware's TX/RX nets).
struct SerialPort {
    std::string name;  // the part's name
    Mcu* mcu = nullptr;  // the MCU it talks to (its clock)
    HostConnector* connector = nullptr;
    std::string location;  // the part's file:line
    const HostProtocol& protocol() const { return connector->protocol(); }
    SerialLink& link() const { return connector->link(); }
};

// A host's options as the board file's serial port declares them.
UartHostOptions default_host_options(const SerialPort& port);

class Bench final : public RunView {
public:
    // The ELF runs on the board's first MCU.
    Bench(const std::string& board_file, const std::string& elf);
    // MCU name -> ELF; MCUs not listed use the board file's `firmware:`.
    Bench(const std::string& board_file, const std::map<std::string, std::string>& firmware);
    explicit Bench(BoardSpec spec, const std::map<std::string, std::string>& firmware);
    ~Bench();
    Bench(const Bench&) = delete;
    Bench& operator=(const Bench&) = delete;

    Board& board() { return *board_; }
    Mcu& mcu(const std::string& name = "") { return board_->mcu(name); }
    Axis& axis(const std::string& name) { return board_->part_as<Axis>(name); }

    // The UART host on serial port `port` of the board file ("" = the first),
    // created on first use with the port's flow control and buffer size
    // unless `options` is given then.
    UartHost& host(const std::string& port = "", std::optional<UartHostOptions> options = std::nullopt);
    bool has_host() const { return !hosts_.empty(); }
    // The link behind serial port `port` of the board file ("" = the first):
    // raw bytes to the firmware (send) and everything it transmitted.
    SerialLink& serial(const std::string& port = "");
    // BadInput naming the ports for an unknown one, or when there is none.
    const SerialPort& serial_port(const std::string& port = "") const;
    const std::vector<SerialPort>& serial_ports() const { return serial_ports_; }

    // Records every MCU pin on a net or named by a label, every serial port's
    // transmitted bytes, and every part signal (call before running).
    void trace_board();
    Timeline& timeline() { return timeline_; }
    Recorder& recorder() { return recorder_; }

    // Bytes from a person or a script (Python's port.write) to serial port
    // `port`: each line in them is one the firmware must answer before the
    // run is done (any line it prints after taking it answers it on a
    // generic port; its family's ok or error on a known one).
    void write(const std::string& port, const std::string& bytes);

    void run_for(double seconds) { board_->run_for_seconds(seconds); }
    // Whether the firmware is not yet done, and with `why` one phrase per
    // thing still going there. Done means: every host finished its job
    // (every line answered, or the host gave up); every line written by hand
    // taken and answered; no part still going (a motion oracle's accepted
    // move not made: Part::still_going); every heater with a target within
    // its band or no longer changing (run/HeatTargets.hpp); and no STEP
    // edge, nor a line either way on a port, for `settle_ps` or 2.5 times
    // the longest step interval of the run (up to 250 ms) if that is longer.
    bool still_going(Picoseconds settle_ps, std::vector<std::string>* why = nullptr) const;
    // Reads the heaters' temperatures for still_going's "no longer changing"
    // (run_until_idle does it between its slices; a caller running its own
    // slices does it after each).
    void sample_heaters();
    // What was still going when the last run_until_idle ended otherwise than idle.
    const std::vector<std::string>& left_going() const { return left_going_; }
    // Runs until done (see still_going) or until `max_ps` of simulated time
    // from now has passed. Every pass of its loop advances simulated time.
    IdleResult run_until_idle_ps(Picoseconds max_ps, Picoseconds settle_ps = 50 * kPsPerMs);
    IdleResult run_until_idle(double max_seconds, double settle_seconds = 0.05);
    // Runs to `end_ps` (simulated, from power-on) in slices of at most
    // 10 ms, calling `after_slice` after each (progress, streaming a VCD).
    // With `until_idle` it ends when the run is idle as run_until_idle_ps
    // says (settle `settle_ps`); it always ends at a halt or SIGINT/SIGTERM.
    struct RunSlices {
        bool until_idle = false;
        Picoseconds settle_ps = 50 * kPsPerMs;
        std::function<void()> after_slice;
        std::function<bool()> stop_when;  // checked after each slice: true ends the run (Idle)
        Picoseconds slice_ps = 0;         // 0: a hundredth of the run, from 1 ms to 10 ms
    };
    IdleResult run_to_ps(Picoseconds end_ps, const RunSlices& how);
    Picoseconds now_ps() const { return board_->now_ps(); }
    double now_seconds() const override { return board_->now_seconds(); }
    // Simulated time of the last STEP edge any driver counted, or -1.
    double last_step_seconds() const { return last_step_ps_ ? seconds_from_ps(*last_step_ps_) : -1.0; }

    // A program the firmware takes in another form (seed 002's binary
    // records made from this G-code): the board's motion judges are told
    // its moves up front, in order, as if each line had been accepted.
    // `source` names it in findings ("drawing.dxf's G-code").
    void command_program(const std::string& gcode, const std::string& source);
    // How the motion judges tell that the job's every line or record was
    // answered (a host's own job is wired by the bench; a record job's by
    // its runner).
    void judge_job_by(const std::function<bool()>& all_answered) const;

    // Board findings plus one HostProtocol finding per host error, alarm,
    // fatal answer or timeout.
    std::vector<Finding> findings() const override;

    // What the HTML report needs about this run (the timeline must be traced).
    RunReport make_report(const std::string& title) const;
    // The signals whose events make_report reads (by SignalId): the parts'
    // signals that declare a role (positions, temperatures, heater duty,
    // servo angles) and each MCU's TWI bytes. A streamed run keeps only
    // these in memory (Timeline::keep_when_taken) and still reports the same.
    std::vector<bool> report_signal_mask() const;

    // What a report reads of the run (trace/ReportOfRun.hpp).
    const Timeline& timeline() const override { return timeline_; }
    std::vector<Mcu*> mcus() const override;
    std::vector<Part*> parts() const override;
    std::string board_path() const override;
    std::vector<TranscriptLine> transcript() const override;
    std::map<const Part*, std::vector<std::pair<double, double>>> temperature_targets(
        const std::vector<Part*>& plants) const override;

private:
    void watch_motion();
    // G0/G1 targets the firmware answers ok to, checked against the board's
    // machines that can judge them (parts/DeltaRobot: target-out-of-reach);
    // and every line the host sends handed to the board's motion judges
    // (parts/CommandedMoves: a motion_oracle), taken back if refused.
    void check_accepted_moves(UartHost& host);
    void follow_sent_lines(UartHost& host);
    std::vector<CommandedMoves*> motion_judges() const;

    // The serial port of host `name` (one that exists).
    const SerialPort& port_of(const std::string& name) const { return serial_port(name); }
    std::unique_ptr<Board> board_;
    std::vector<SerialPort> serial_ports_;
    Timeline timeline_;
    Recorder recorder_{timeline_};
    std::map<std::string, std::unique_ptr<UartHost>> hosts_;
    // Lines a host's firmware refused that the machine cannot reach either
    // (check_accepted_moves): right answers, not findings.
    std::set<std::pair<const UartHost*, std::size_t>> right_refusals_;
    std::optional<Picoseconds> last_step_ps_;
    // The longest time between two STEP edges of one part, up to
    // kLongestStepIntervalCounted (longer is a machine at rest between moves).
    Picoseconds longest_step_interval_ps_ = 0;
    std::map<const Part*, Picoseconds> last_step_by_part_ps_;
    std::unique_ptr<HeatTargets> heat_;
    // Lines written by hand on one port, from the link's byte count to the answer.
    struct HandWritten {
        std::uint64_t delivered = 0;            // bytes the link delivered since the bench watched it
        std::uint64_t written_end = 0;          // the byte number after the last byte written by hand
        std::deque<std::pair<std::uint64_t, std::string>> untaken;  // each line's '\n' byte number and text
        std::deque<std::pair<Cycle, std::string>> unanswered;        // taken at that cycle, not yet answered
        std::string partial;                    // the firmware's line so far
    };
    std::map<std::string, HandWritten> hand_;
    void watch_port(const SerialPort& port);
    // run_until_idle_ps without noting what was left going (run_to_ps's slices).
    IdleResult run_until_done(Picoseconds max_ps, Picoseconds settle_ps);
    IdleResult noting_what_is_going(IdleResult r, Picoseconds settle_ps);
    mutable std::vector<std::string> left_going_;
    bool traced_ = false;
};

}  // namespace avrbench
