// A host on one USART of one MCU that streams G-code the way real senders do:
// Marlin/Teacup "send one line, wait for ok", or grbl's character counting
// (keep the firmware's receive buffer as full as it can take). It parses the
// firmware's answers into lines (ok, error[:N], !!, ALARM:N, anything else),
// keeps a transcript with cycles, and stops with a message naming the line
// when the firmware does not answer within a simulated-time timeout.
//
//   Mcu mcu(ElfImage::load("grbl.elf"));
//   UartHost host(mcu, 0, {.flow = FlowControl::CharacterCounting});
//   host.load_file("job.gcode");
//   host.run_until_finished(10.0);   // simulated seconds
//   EXPECT_TRUE(host.done()) << host.failure_message() << host.tail(10);
//
// All time is the MCU's simulated time (its Scheduler); nothing waits on the
// wall clock.
#pragma once

#include "core/Finding.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/Time.hpp"
#include "core/SerialLink.hpp"
#include "core/TextPattern.hpp"
#include "stimulus/HostFamily.hpp"

namespace avrbench {

class Mcu;

enum class FlowControl {
    // Marlin / Teacup / grbl's simple mode: one line, then wait for its
    // answer; never more than one unanswered line.
    SendAndWait,
    // grbl's stream.py "aggressive" mode: send while the bytes of all
    // unanswered lines (each with its '\n') plus the next line fit the
    // firmware's receive buffer; each ok/error answers the oldest line.
    CharacterCounting,
};

const char* to_string(FlowControl flow);
// "send_and_wait" or "character_counting" (the board files' spelling).
// Throws BadInput naming `what` for anything else.
FlowControl parse_flow_control(std::string_view text, std::string_view what);

// A generic firmware's port that would start at once waits for the firmware's
// first output line instead, at most `boot_s`, then starts (the fuzz target's
// boot, and its reproducers' replay: bench/fuzz/FirmwareTarget.hpp).
struct UartHostOptions;
void start_generic_after_boot(UartHostOptions& options, double boot_s);

enum class Startup {
    Immediately,    // send as soon as there are lines (Uart::send still waits for RXEN)
    WaitForBanner,  // wait for the firmware's first output line (or one containing banner_contains)
    FixedDelay,     // wait startup_delay_s of simulated time
};

// What the firmware on the other end speaks (its welcome, unsolicited
// output and answers): stimulus/HostFamily.hpp, docs/HOSTS.md.

struct UartHostOptions {
    FlowControl flow = FlowControl::SendAndWait;
    FirmwareFamily family = FirmwareFamily::Generic;
    // A family's welcome: wait for it, then for this long without output
    // (boot chatter: settings, SD card probes) before the first line.
    // Assumed: 200 ms, longer than any boot message burst at 115200 baud.
    double quiet_after_welcome_s = 0.2;
    // Commands that take long by design (G4, M109, M190, M116, G28, G29, $H)
    // get this timeout, or the dwell time plus line_timeout_s for G4. Any
    // output from the firmware (keep-alives) re-arms every timeout.
    // Assumed: 10 min, longer than any heat-up or homing cycle.
    double long_command_timeout_s = 600.0;
    // grbl: the status query '?' sent this often while lines are unanswered,
    // as grbl senders do (Universal G-code Sender and bCNC poll about every
    // 200 ms); grbl answers with a '<...>' report even mid-move, so a silent
    // grbl is a hung grbl. 0 disables it. Assumed: 250 ms.
    double grbl_status_poll_s = 0.25;
    // Character counting: the firmware's receive buffer. 128 = grbl 1.1's
    // RX_BUFFER_SIZE on the ATmega328P (grbl/serial.h).
    std::size_t rx_buffer_bytes = 128;
    // No answer and no other output for this long (simulated) while a line
    // is unanswered: stop and record a timeout. 0: the family's
    // (default_line_timeout_s). It is never shorter than 2.5 times the
    // longest pause between outputs seen while a line was unanswered: the
    // firmware's keep-alive period, learned from the run.
    double line_timeout_s = 0;
    Startup startup = Startup::Immediately;
    std::string banner_contains;     // WaitForBanner: empty = the first line, whatever it says
    double banner_timeout_s = 2.0;   // WaitForBanner: give up (failed) after this long
    bool start_without_banner = false;  // WaitForBanner: at banner_timeout_s start anyway (a firmware that may print nothing)
    double startup_delay_s = 0.0;    // FixedDelay
    // Lines the firmware prints that are errors besides its family's own
    // (stimulus/HostFamily.hpp): RE2 patterns searched in every line that
    // answers nothing else. Such a line is an error about the oldest
    // unanswered line (or the last answered one); it answers no line itself.
    std::vector<std::string> error_patterns;
    bool stop_on_error = false;  // stop streaming (failed) at the first error
    bool stop_on_alarm = true;   // grbl ALARM:N stops streaming (failed)
    // A fatal message stops streaming (failed): "!!" (Teacup, Repetier,
    // Marlin 2 with its host protocol), "fatal:", and Marlin's kill()
    // "Error:Printer halted. kill() called!".
    bool stop_on_fatal = true;
    // Binary protocols: no line parsing of the firmware's output; use
    // send_bytes() and received(). Lines cannot be queued in this mode.
    bool raw_bytes = false;
};

// One line of a job after comment stripping, with where it came from.
struct GcodeLine {
    std::string text;        // as sent, without the '\n'
    std::size_t number = 0;  // 1-based line number in `origin`
    std::string origin;      // the file path, or "<lines>" for add_line(s)
};

// A job line as messages quote it: whole up to 80 bytes, else its start and
// its length (a 100 kB line must not become a 100 kB error message); control
// bytes as \xNN.
std::string quoted_line(const std::string& text);

// The job's lines, each sent byte for byte as written (leading and
// trailing blanks included) but for its comments: "; ..." to the end of
// the line and "( ... )" (an unclosed '(' runs to the end), each with the
// blanks before it. Lines left blank are dropped. Accepts "\n", "\r\n"
// and lone "\r" line ends. `first_number` is the number of the first line
// of `text`.
std::vector<GcodeLine> parse_gcode(std::string_view text, const std::string& origin, std::size_t first_number = 1);

// A job file's bytes checked as text before streaming: a UTF-16 file, a NUL
// or other control byte (tab and line ends aside) and bytes that are not
// UTF-8 are BadInput "file:line: ..." naming the byte (never echoing it); a
// UTF-8 byte-order mark is skipped. Returns the text to parse.
std::string_view checked_gcode_text(std::string_view text, const std::string& origin);

enum class Direction { Sent, Received };

struct TranscriptEntry {
    Cycle cycle = 0;        // Sent: when the host handed the line to the port;
                            // Received: the UDR write of the line's last byte
    Direction direction = Direction::Sent;
    std::string text;       // without line end
    std::size_t source_line = 0;  // Sent lines: their number in the job (0: raw bytes)
};

enum class HostEventKind {
    Error,          // "error..." / "Error..." answer
    Alarm,          // "ALARM..." (grbl)
    Fatal,          // "!!...", "fatal:...", "Error:Printer halted..."
    Timeout,        // a line got no answer within line_timeout_s
    BannerTimeout,  // WaitForBanner: no banner within banner_timeout_s
    LineTooLong,    // character counting: a line longer than the receive buffer can never be sent
    Restarted,      // the family's welcome came again mid-job: the firmware reset
    ResendLoop,     // the firmware asked for the same line again and again (Marlin's Resend:)
};

const char* to_string(HostEventKind kind);

struct HostEvent {
    HostEventKind kind = HostEventKind::Error;
    Cycle cycle = 0;
    std::string response;            // the firmware's line, empty for timeouts
    std::optional<GcodeLine> line;   // Error: the line it answered; Timeout/LineTooLong: that line;
                                     // Alarm/Fatal: the oldest unanswered line, if any
    std::string message;             // one line for people
};

class UartHost {
public:
    // What this one finds (`avrbench findings` lists every kind).
    static const FindingKind kHostProtocol;  // host-protocol
    using LineListener = std::function<void(const TranscriptEntry& entry)>;

    // Attaches to USART `uart_index` of `mcu` from its current cycle on (the
    // startup timers start now). The host must not outlive the MCU; the MCU
    // may outlive the host.
    UartHost(Mcu& mcu, int uart_index = 0, UartHostOptions options = {});
    // On any serial link clocked by `clock` (a board's serial_host part:
    // a USART or two bit-banged pins).
    UartHost(Mcu& clock, SerialLink& link, UartHostOptions options = {});
    ~UartHost();
    UartHost(const UartHost&) = delete;
    UartHost& operator=(const UartHost&) = delete;

    const UartHostOptions& options() const { return options_; }

    // --- the job ---------------------------------------------------------
    // Throws BadInput "<path>: no such file" / "<path>: cannot read".
    void load_file(const std::string& path);
    // Lines of text ('\n'-separated), numbered on from the previous add_line(s).
    void add_lines(std::string_view text);
    void add_line(std::string_view text) { add_lines(text); }
    const std::vector<GcodeLine>& lines() const { return lines_; }

    // --- raw bytes (binary protocols; grbl's real-time '?', '!', '~') ----
    // Sent at once (not counted against the receive buffer, as grbl's
    // real-time commands are not), recorded in the transcript as Sent with
    // source_line 0.
    void send_bytes(const std::string& bytes);
    // Sends `bytes` the same way when the MCU reaches `at_cycle` (grbl's feed
    // hold '!' and resume '~' at chosen times); the job is not done() while
    // any are still to go.
    void send_bytes_at(const std::string& bytes, Cycle at_cycle);
    // Every byte the firmware transmitted since the host attached.
    const std::vector<UartByte>& received() const { return received_; }
    std::string received_text() const;

    // --- state -------------------------------------------------------------
    bool ready() const { return ready_; }         // startup finished, lines may go out
    std::size_t lines_sent() const { return next_; }
    std::size_t lines_acknowledged() const { return acknowledged_; }
    // All lines sent and answered, and not failed.
    bool done() const;
    // Streaming stopped for good: timeout, ALARM/!! (per options), an error
    // with stop_on_error, a banner timeout, a line too long.
    bool failed() const { return failed_; }
    bool finished() const { return done() || failed(); }
    // The event that stopped the host, as one line ("" while not failed).
    std::string failure_message() const;

    std::size_t outstanding_lines() const { return outstanding_.size(); }
    std::size_t outstanding_bytes() const { return outstanding_bytes_; }
    std::size_t max_outstanding_lines() const { return max_outstanding_lines_; }
    std::size_t max_outstanding_bytes() const { return max_outstanding_bytes_; }

    // --- answers -----------------------------------------------------------
    std::size_t oks() const { return oks_; }
    // Error answers (each family's, docs/HOSTS.md), counted as they come.
    std::size_t errors() const { return errors_; }
    // Job lines an error answer was about (a line the firmware asked for
    // again and then took is not among them).
    std::size_t lines_errored() const;
    bool line_errored(std::size_t index) const { return index < line_errored_.size() && line_errored_[index]; }
    std::size_t resends() const { return resends_; }
    std::size_t status_polls() const { return status_polls_; }  // grbl '?' sent as keep-alive queries
    // Answers that came with no line outstanding (a boot "ok", say).
    std::size_t unsolicited_oks() const { return unsolicited_acks_; }
    std::size_t alarms() const { return alarms_; }
    std::size_t fatals() const { return fatals_; }
    // ok/error answers that arrived with no line outstanding.
    std::size_t unsolicited_acks() const { return unsolicited_acks_; }
    const std::vector<HostEvent>& events() const { return events_.all(); }
    // The last time the firmware said it is busy (stimulus/HostFamily.hpp
    // is_busy_report) after its last answer (ok or error: a busy report
    // while a line waited is about that line), with what it said.
    std::optional<Cycle> last_busy_cycle() const { return last_busy_cycle_; }
    const std::string& last_busy_text() const { return last_busy_text_; }
    const std::optional<std::string>& banner() const { return banner_; }

    // --- transcript ----------------------------------------------------------
    const std::vector<TranscriptEntry>& transcript() const { return transcript_; }
    // The last `n` entries, one per line: "   0.012345 s > G1 X10" / "< ok".
    std::string tail(std::size_t n) const;
    // Called for every line received (after the host has handled it).
    void on_line_received(LineListener fn) { line_listeners_.push_back(std::move(fn)); }
    // Called when an ok or error answers job line `index` (not a realtime
    // byte; not a Resend's ok), `refused` when the answer or an error before
    // it refused the line; before the next line goes out.
    using AnswerListener = std::function<void(const GcodeLine& line, std::size_t index, bool refused)>;
    void on_answer(AnswerListener fn) { answer_listeners_.push_back(std::move(fn)); }
    // The cycle (of this host's MCU) of the machine's last visible work - a
    // STEP edge on the board -, if any: a line waiting while the machine
    // moves is not timed out; its timeout counts from the last step
    // (a firmware that answers a move when it is done, however long it takes).
    void set_activity_probe(std::function<std::optional<Cycle>()> probe) { activity_probe_ = std::move(probe); }
    // Called when a job line first goes out (not for resends, nor for grbl's
    // real-time bytes), before the firmware has its first byte.
    using SentListener = std::function<void(const GcodeLine& line)>;
    void on_line_sent(SentListener fn) { sent_listeners_.push_back(std::move(fn)); }
    // Called when bytes go out that are not a job line: grbl's real-time
    // commands ('!', '?', '~' on a line of their own) and timed bytes
    // (send_bytes_at, --realtime).
    using BytesListener = std::function<void(const std::string& bytes)>;
    void on_bytes_sent(BytesListener fn) { bytes_listeners_.push_back(std::move(fn)); }

    // --- running -------------------------------------------------------------
    // Runs the MCU until finished() or `max_seconds` of simulated time from
    // now (or the MCU halts). Returns finished(). For several MCUs in
    // lockstep, run the lockstep and poll finished() instead.
    bool run_until_finished(double max_seconds);

    // The line timeout in force: the configured (or the family's), raised to
    // 2.5 times the keep-alive period seen so far.
    double line_timeout_s() const;

private:
    // An event about the oldest unanswered line (if any), with the firmware's answer.
    HostEvent event_at_oldest_line(HostEventKind kind, Cycle cycle, const std::string& response) const;
    std::optional<std::size_t> line_of_error(const std::string& text) const;
    void record_error(Cycle cycle, const std::string& text);
    static std::string after_line(const HostEvent& event);  // " after line N 'text'" or ""
    void stop_or_record(bool stop, HostEvent event);

    void poll_status(std::uint64_t generation);
    std::uint64_t poll_generation_ = 0;
    std::size_t status_polls_ = 0;

    void arm_quiet_timer();
    void resend(Cycle cycle, const std::string& text);
    double timeout_for_oldest_s() const;
    Cycle last_output_cycle_ = 0;     // the last line the firmware printed
    double keepalive_pause_s_ = 0;    // the longest pause between outputs while a line waited
    std::uint64_t quiet_generation_ = 0;
    std::size_t resends_ = 0;
    bool resend_on_next_ok_ = false;
    std::size_t resends_of_oldest_ = 0;  // Resend: answers since the oldest line was last acknowledged

    struct Outstanding {
        std::size_t index;  // into lines_
        std::size_t bytes;  // text + '\n'
    };

    void on_byte(Cycle cycle, std::uint8_t byte);
    void on_line(Cycle cycle, std::string text);
    // Frees the oldest line; true when the next may go out (on_line pumps
    // after its listeners).
    bool acknowledge();
    void become_ready();
    void pump();
    void send_line(std::size_t index);
    void arm_line_timeout();
    void schedule_line_timeout(std::uint64_t generation, Cycle at);
    void on_line_timeout();
    void fail(HostEvent event);
    void record(HostEvent event);
    void check_finished();
    std::string seconds_text(double seconds) const;

    Mcu& mcu_;
    SerialLink& uart_;
    UartHostOptions options_;
    std::shared_ptr<bool> alive_;  // callbacks held by the Uart and the Scheduler check it

    std::vector<GcodeLine> lines_;
    std::vector<bool> line_errored_;  // per line of lines_
    std::vector<TextPattern> error_patterns_;
    std::size_t next_ = 0;           // next line to send
    std::size_t timed_bytes_pending_ = 0;  // send_bytes_at() calls not yet due
    std::size_t acknowledged_ = 0;
    std::size_t added_raw_lines_ = 0;  // numbering for add_lines
    std::deque<Outstanding> outstanding_;
    std::size_t outstanding_bytes_ = 0;
    std::size_t max_outstanding_lines_ = 0;
    std::size_t max_outstanding_bytes_ = 0;

    bool ready_ = false;
    bool failed_ = false;
    std::uint64_t timeout_generation_ = 0;
    Cycle timeout_armed_cycle_ = 0;  // when the running line timeout started counting
    std::function<std::optional<Cycle>()> activity_probe_;
    bool stop_mcu_when_finished_ = false;

    std::vector<UartByte> received_;
    std::string partial_line_;
    bool last_was_cr_ = false;

    std::size_t oks_ = 0, errors_ = 0, alarms_ = 0, fatals_ = 0, unsolicited_acks_ = 0;
    FindingLog<HostEvent> events_;
    std::optional<std::size_t> failure_event_;
    std::optional<Cycle> last_busy_cycle_;
    std::string last_busy_text_;
    std::optional<std::string> banner_;
    std::vector<TranscriptEntry> transcript_;
    std::vector<LineListener> line_listeners_;
    std::vector<SentListener> sent_listeners_;
    std::vector<BytesListener> bytes_listeners_;
    std::vector<AnswerListener> answer_listeners_;
};

}  // namespace avrbench
