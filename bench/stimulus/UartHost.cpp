#include "stimulus/UartHost.hpp"

#include "core/GcodeLexer.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "mcu/Mcu.hpp"
#include "core/Scheduler.hpp"

namespace avrbench {

const FindingKind UartHost::kHostProtocol = FindingKind::declare("host-protocol", "the UART host saw error / ALARM / !! or got no answer", Severity::Warning);

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// A line as it goes out: byte for byte as written (a line's length is
// what a firmware's buffer limits are tested with), but for its comments -
// "; ..." to the end and "( ... )", an unclosed '(' to the end. The blanks
// around an inline comment stay; those before a comment that ends the line
// go with it, as hosts such as Printrun send them. A line of nothing but
// blanks and comments is no line ("").
std::string strip_comments(std::string_view raw) {
    std::string out;
    out.reserve(raw.size());
    bool in_paren = false, comment_at_end = false;
    for (char c : raw) {
        if (in_paren) {
            if (c == ')') in_paren = false;
            continue;
        }
        if (c == ';') {
            comment_at_end = true;
            break;
        }
        if (c == '(') {
            in_paren = comment_at_end = true;
            continue;
        }
        if (!is_space(c)) comment_at_end = false;
        out.push_back(c);
    }
    if (comment_at_end) {
        while (!out.empty() && is_space(out.back())) out.pop_back();
    }
    if (std::all_of(out.begin(), out.end(), is_space)) return "";
    return out;
}

// Printable form of a transcript text for tail(): control bytes as \xNN.
std::string printable(const std::string& text) { return hex_escaped(text); }

}  // namespace

std::string quoted_line(const std::string& text) {
    constexpr std::size_t kShown = 60;
    if (text.size() <= 80) return "'" + printable(text) + "'";
    return "'" + printable(text.substr(0, kShown)) + "...' (" + std::to_string(text.size()) + " bytes)";
}

const char* to_string(FlowControl flow) {
    switch (flow) {
        case FlowControl::SendAndWait: return "send_and_wait";
        case FlowControl::CharacterCounting: return "character_counting";
    }
    return "?";
}

FlowControl parse_flow_control(std::string_view text, std::string_view what) {
    if (text == "send_and_wait") return FlowControl::SendAndWait;
    if (text == "character_counting") return FlowControl::CharacterCounting;
    throw BadInput(std::string(what) + ": flow '" + std::string(text) +
                   "' is not send_and_wait or character_counting");
}

const char* to_string(HostEventKind kind) {
    switch (kind) {
        case HostEventKind::Error: return "error";
        case HostEventKind::Alarm: return "alarm";
        case HostEventKind::Fatal: return "fatal";
        case HostEventKind::Timeout: return "timeout";
        case HostEventKind::BannerTimeout: return "banner-timeout";
        case HostEventKind::LineTooLong: return "line-too-long";
        case HostEventKind::Restarted: return "restarted";
        case HostEventKind::ResendLoop: return "resend-loop";
    }
    return "?";
}

std::vector<GcodeLine> parse_gcode(std::string_view text, const std::string& origin, std::size_t first_number) {
    std::vector<GcodeLine> out;
    std::size_t number = first_number;
    std::size_t start = 0;
    while (start <= text.size()) {
        // "\n", "\r\n" and a lone "\r" (old Mac files) each end a line.
        std::size_t end = text.find_first_of("\r\n", start);
        const bool last = end == std::string_view::npos;
        if (last) end = text.size();
        // A final line end ends the last line; it does not start an empty one.
        if (last && start == text.size() && start != 0) break;
        std::string stripped = strip_comments(text.substr(start, end - start));
        if (!stripped.empty()) out.push_back(GcodeLine{std::move(stripped), number, origin});
        ++number;
        if (last) break;
        start = end + (text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n' ? 2 : 1);
    }
    return out;
}

std::string_view checked_gcode_text(std::string_view text, const std::string& origin) {
    auto byte_text = [](unsigned char b) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "0x%02x", b);
        return std::string(buf);
    };
    if (text.size() >= 2 && ((static_cast<unsigned char>(text[0]) == 0xff && static_cast<unsigned char>(text[1]) == 0xfe) ||
                             (static_cast<unsigned char>(text[0]) == 0xfe && static_cast<unsigned char>(text[1]) == 0xff))) {
        throw BadInput(origin + ":1: UTF-16 text (byte-order mark " + byte_text(static_cast<unsigned char>(text[0])) + " " +
                       byte_text(static_cast<unsigned char>(text[1])) + "); save the job as ASCII or UTF-8");
    }
    // A UTF-8 byte-order mark (Windows editors write one) is not G-code: skip it.
    if (text.size() >= 3 && text.substr(0, 3) == "\xef\xbb\xbf") text.remove_prefix(3);
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < text.size(); ++i, ++column) {
        const auto b = static_cast<unsigned char>(text[i]);
        if (b == '\n' || (b == '\r' && (i + 1 >= text.size() || text[i + 1] != '\n'))) {
            ++line;
            column = 0;
            continue;
        }
        if (b == '\r' || b == '\t') continue;
        if (b < 0x20 || b == 0x7f) {
            throw BadInput(origin + ":" + std::to_string(line) + ": control byte " + byte_text(b) + " at column " +
                           std::to_string(column) + " is not G-code text");
        }
        if (b < 0x80) continue;
        // Multi-byte UTF-8 (in comments, say) is text; anything else is not.
        const std::size_t n = (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xe ? 3 : (b >> 3) == 0x1e ? 4 : 0;
        bool ok = n != 0 && i + n <= text.size();
        for (std::size_t k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
        if (!ok) {
            throw BadInput(origin + ":" + std::to_string(line) + ": byte " + byte_text(b) + " at column " +
                           std::to_string(column) + " is not UTF-8 text");
        }
        i += n - 1;
    }
    return text;
}

UartHost::UartHost(Mcu& mcu, int uart_index, UartHostOptions options)
    : UartHost(mcu, mcu.uart(uart_index), std::move(options)) {}

UartHost::UartHost(Mcu& mcu, SerialLink& link, UartHostOptions options)
    : mcu_(mcu), uart_(link), options_(std::move(options)), alive_(std::make_shared<bool>(true)) {
    if (options_.flow == FlowControl::CharacterCounting && options_.rx_buffer_bytes == 0) {
        throw BadInput("UART host: rx_buffer_bytes must be at least 1 for character counting");
    }
    uart_.connect_host();
    if (options_.line_timeout_s == 0) options_.line_timeout_s = default_line_timeout_s(options_.family);
    if (!(options_.line_timeout_s > 0.0)) throw BadInput("UART host: line timeout must be positive");
    if (options_.family != FirmwareFamily::Generic && options_.startup == Startup::Immediately) {
        // A known family: start after its welcome and the boot chatter that follows.
        options_.startup = Startup::WaitForBanner;
        if (options_.banner_timeout_s < 10.0) options_.banner_timeout_s = 10.0;  // SD probes take seconds
    }
    for (const std::string& p : options_.error_patterns) error_patterns_.emplace_back(p, "error pattern");

    std::weak_ptr<bool> alive = alive_;
    uart_.on_transmit([this, alive](Cycle cycle, std::uint8_t byte) {
        if (alive.expired()) return;
        on_byte(cycle, byte);
    });

    switch (options_.startup) {
        case Startup::Immediately:
            ready_ = true;
            break;
        case Startup::FixedDelay:
            mcu_.scheduler().after(mcu_.cycles_from_seconds(options_.startup_delay_s), [this, alive](Cycle) {
                if (alive.expired()) return;
                become_ready();
            });
            break;
        case Startup::WaitForBanner:
            mcu_.scheduler().after(mcu_.cycles_from_seconds(options_.banner_timeout_s), [this, alive](Cycle) {
                if (alive.expired() || ready_ || failed_) return;
                if (banner_ && options_.family != FirmwareFamily::Generic) {
                    become_ready();  // welcomed, but never quiet: start anyway
                    return;
                }
                if (options_.start_without_banner) {
                    become_ready();
                    return;
                }
                HostEvent e;
                e.kind = HostEventKind::BannerTimeout;
                e.cycle = mcu_.cycle();
                const char* welcome = welcome_text(options_.family);
                e.message = options_.family != FirmwareFamily::Generic
                                ? std::string("no welcome '") + welcome + "' from the " + to_string(options_.family) +
                                      " firmware within " + seconds_text(options_.banner_timeout_s)
                            : options_.banner_contains.empty()
                                ? "no banner from the firmware within " + seconds_text(options_.banner_timeout_s)
                                : "no banner containing '" + options_.banner_contains + "' from the firmware within " +
                                      seconds_text(options_.banner_timeout_s);
                fail(std::move(e));
            });
            break;
    }
}

UartHost::~UartHost() {
    // The Uart and the Scheduler keep the callbacks; they see the host gone.
    alive_.reset();
}

// --- the job -----------------------------------------------------------------

void UartHost::load_file(const std::string& path) {
    if (options_.raw_bytes) throw std::logic_error("UartHost: raw_bytes mode sends no lines; use send_bytes()");
    const std::string bytes = read_input_file(path, "G-code file", kMaxGcodeFileBytes);
    auto parsed = parse_gcode(checked_gcode_text(bytes, path), path);
    lines_.insert(lines_.end(), std::make_move_iterator(parsed.begin()), std::make_move_iterator(parsed.end()));
    line_errored_.resize(lines_.size(), false);
    pump();
}

void UartHost::add_lines(std::string_view text) {
    if (options_.raw_bytes) throw std::logic_error("UartHost: raw_bytes mode sends no lines; use send_bytes()");
    auto parsed = parse_gcode(text, "<lines>", added_raw_lines_ + 1);
    // Count the raw lines (comments and blanks included) for the numbering.
    std::size_t raw = 1;
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (text[i] == '\n' && i + 1 < text.size()) ++raw;
    }
    added_raw_lines_ += raw;
    lines_.insert(lines_.end(), std::make_move_iterator(parsed.begin()), std::make_move_iterator(parsed.end()));
    line_errored_.resize(lines_.size(), false);
    pump();
}

// --- raw bytes ---------------------------------------------------------------

void UartHost::send_bytes(const std::string& bytes) {
    transcript_.push_back(TranscriptEntry{mcu_.cycle(), Direction::Sent, bytes, 0});
    uart_.send(bytes);
    for (auto& fn : bytes_listeners_) fn(bytes);
}

void UartHost::send_bytes_at(const std::string& bytes, Cycle at_cycle) {
    ++timed_bytes_pending_;
    std::weak_ptr<bool> alive = alive_;
    mcu_.scheduler().at(std::max(at_cycle, mcu_.cycle()), [this, alive, bytes](Cycle) {
        if (alive.expired()) return;
        --timed_bytes_pending_;
        send_bytes(bytes);
    });
}

std::string UartHost::received_text() const {
    std::string out;
    out.reserve(received_.size());
    for (const auto& b : received_) out.push_back(static_cast<char>(b.value));
    return out;
}

// --- state -------------------------------------------------------------------

bool UartHost::done() const {
    return ready_ && !failed_ && next_ == lines_.size() && outstanding_.empty() && timed_bytes_pending_ == 0;
}

std::string UartHost::failure_message() const {
    if (!failure_event_) return "";
    return events_.all()[*failure_event_].message;
}

void start_generic_after_boot(UartHostOptions& options, double boot_s) {
    if (options.family != FirmwareFamily::Generic || options.startup != Startup::Immediately || options.raw_bytes) return;
    options.startup = Startup::WaitForBanner;
    options.banner_contains.clear();
    options.banner_timeout_s = boot_s;
    options.start_without_banner = true;
}

// --- receiving -----------------------------------------------------------------

void UartHost::on_byte(Cycle cycle, std::uint8_t byte) {
    received_.push_back({cycle, byte});
    if (options_.raw_bytes) {
        if (!ready_ && options_.startup == Startup::WaitForBanner && !failed_) become_ready();
        return;
    }
    // Lines end in "\n", "\r\n" or a lone "\r".
    if (byte == '\n') {
        if (last_was_cr_) {
            last_was_cr_ = false;  // the '\n' of "\r\n": the line already ended at the '\r'
            return;
        }
        on_line(cycle, std::move(partial_line_));
        partial_line_.clear();
        return;
    }
    last_was_cr_ = byte == '\r';
    if (byte == '\r') {
        on_line(cycle, std::move(partial_line_));
        partial_line_.clear();
        return;
    }
    partial_line_.push_back(static_cast<char>(byte));
}

void UartHost::on_line(Cycle cycle, std::string text) {
    // A copy: answering may send lines, which grows the transcript.
    const TranscriptEntry entry{cycle, Direction::Received, text, 0};
    transcript_.push_back(entry);

    // Any output is a sign of life: every timeout starts again. The longest
    // pause between two outputs while a line waits is the firmware's
    // keep-alive period: the line timeout stays 2.5 times above it.
    if (!outstanding_.empty() && last_output_cycle_ != 0 && cycle > last_output_cycle_) {
        const double pause_s = static_cast<double>(cycle - last_output_cycle_) / mcu_.frequency_hz();
        keepalive_pause_s_ = std::max(keepalive_pause_s_, pause_s);
    }
    last_output_cycle_ = cycle;
    if (!failed_ && !outstanding_.empty()) arm_line_timeout();

    const FirmwareFamily family = options_.family;
    if (is_busy_report(family, text)) {
        last_busy_cycle_ = cycle;
        last_busy_text_ = text;
    }
    AnswerKind kind = classify_answer(family, text);
    if (kind == AnswerKind::Text) {
        for (const TextPattern& p : error_patterns_) {
            if (p.found_in(text)) {
                kind = AnswerKind::ErrorNote;
                break;
            }
        }
    }
    bool answered = false;  // a line acknowledged: the next may go out
    // The line an ok or error answered (the oldest unanswered one), if any.
    std::optional<std::size_t> answered_index;
    const auto oldest = [this]() -> std::optional<std::size_t> {
        if (outstanding_.empty()) return std::nullopt;
        return outstanding_.front().index;
    };
    if (!ready_ && options_.startup == Startup::WaitForBanner && !failed_) {
        if (family != FirmwareFamily::Generic) {
            // Everything before the welcome is discarded by the firmware's own
            // init anyway (grbl resets its read buffer); after it, wait for quiet.
            if (kind == AnswerKind::Welcome) banner_ = text;
            if (banner_) arm_quiet_timer();
        } else if (options_.banner_contains.empty() || text.find(options_.banner_contains) != std::string::npos) {
            banner_ = text;
            become_ready();
        }
    } else {
        switch (kind) {
            case AnswerKind::Text: break;  // reports, keep-alives, messages: transcript only
            case AnswerKind::Welcome:
                if (ready_) {
                    HostEvent e = event_at_oldest_line(HostEventKind::Restarted, cycle, text);
                    e.message = "the firmware restarted mid-job (welcome '" + text + "' again" +
                                (e.line ? ", while line " + std::to_string(e.line->number) + " '" + e.line->text + "' was unanswered)"
                                        : ")");
                    fail(std::move(e));
                }
                break;
            case AnswerKind::Resend: resend(cycle, text); break;
            case AnswerKind::Ok:
                if (resend_on_next_ok_) {
                    resend_on_next_ok_ = false;
                    if (!outstanding_.empty()) {
                        const std::size_t index = outstanding_.front().index;
                        // The error that asked for it was about the line as it
                        // arrived, not as the firmware will take it now.
                        line_errored_[index] = false;
                        const GcodeLine& line = lines_[index];
                        transcript_.push_back(TranscriptEntry{cycle, Direction::Sent, line.text, line.number});
                        uart_.send(line.text + "\n");
                    }
                } else {
                    ++oks_;
                    answered_index = oldest();
                    answered = acknowledge();
                    last_busy_cycle_.reset();  // what it was busy with is answered
                }
                break;
            case AnswerKind::Fatal: {
                ++fatals_;
                HostEvent e = event_at_oldest_line(HostEventKind::Fatal, cycle, text);
                e.message = "firmware fatal error '" + text + "'" + after_line(e);
                stop_or_record(options_.stop_on_fatal, std::move(e));
                break;
            }
            case AnswerKind::Error:
            case AnswerKind::ErrorNote:
            case AnswerKind::ResendError:
                record_error(cycle, text);
                if (kind == AnswerKind::Error) {
                    answered_index = oldest();
                    answered = acknowledge();
                    last_busy_cycle_.reset();
                }
                if (kind == AnswerKind::ResendError) resend(cycle, text);
                break;
            case AnswerKind::Alarm: {
                ++alarms_;
                HostEvent e = event_at_oldest_line(HostEventKind::Alarm, cycle, text);
                e.message = "firmware alarm '" + text + "'" + after_line(e);
                stop_or_record(options_.stop_on_alarm, std::move(e));
                break;
            }
        }
    }

    // Listeners hear the answer before the next line goes out: a motion
    // judge takes back a refused line's moves before it reads the next.
    if (answered_index) {
        const bool refused = kind == AnswerKind::Error || line_errored(*answered_index);
        for (auto& fn : answer_listeners_) fn(lines_[*answered_index], *answered_index, refused);
    }
    for (auto& fn : line_listeners_) fn(entry);
    if (answered) {
        pump();
        check_finished();
    }
}

// An error answer is about the line it names (Repetier reports an unknown
// command when it runs, after the ok it queued it with), else about the
// oldest unanswered line, else about the line answered last.
std::optional<std::size_t> UartHost::line_of_error(const std::string& text) const {
    const std::string named = command_named(text);
    const auto names = [&](std::size_t index) { return command_word(lines_[index].text) == named; };
    if (!named.empty()) {
        for (const Outstanding& o : outstanding_) {
            if (names(o.index) && !line_errored_[o.index]) return o.index;
        }
        // Lines answered already, newest first, a receive buffer's worth back.
        const std::size_t answered_end = outstanding_.empty() ? next_ : outstanding_.front().index;
        constexpr std::size_t kLinesLookedBack = 64;  // assumed: deeper than any firmware's command queue
        for (std::size_t i = answered_end; i > 0 && answered_end - i < kLinesLookedBack; --i) {
            if (names(i - 1) && !line_errored_[i - 1]) return i - 1;
        }
    }
    if (!outstanding_.empty()) return outstanding_.front().index;
    if (next_ > 0) return next_ - 1;
    return std::nullopt;
}

void UartHost::record_error(Cycle cycle, const std::string& text) {
    ++errors_;
    HostEvent e;
    e.kind = HostEventKind::Error;
    e.cycle = cycle;
    e.response = text;
    if (const auto index = line_of_error(text)) {
        e.line = lines_[*index];
        line_errored_[*index] = true;
    }
    e.message = e.line ? "line " + std::to_string(e.line->number) + " " + quoted_line(e.line->text) + " got '" + text + "'"
                       : "'" + text + "' with no line sent";
    stop_or_record(options_.stop_on_error, std::move(e));
}

std::size_t UartHost::lines_errored() const {
    return static_cast<std::size_t>(std::count(line_errored_.begin(), line_errored_.end(), true));
}

HostEvent UartHost::event_at_oldest_line(HostEventKind kind, Cycle cycle, const std::string& response) const {
    HostEvent e;
    e.kind = kind;
    e.cycle = cycle;
    e.response = response;
    if (!outstanding_.empty()) e.line = lines_[outstanding_.front().index];
    return e;
}

std::string UartHost::after_line(const HostEvent& e) {
    return e.line ? " after line " + std::to_string(e.line->number) + " '" + e.line->text + "'" : "";
}

void UartHost::stop_or_record(bool stop, HostEvent event) {
    if (stop) {
        fail(std::move(event));
    } else {
        record(std::move(event));
    }
}

bool UartHost::acknowledge() {
    if (outstanding_.empty()) {
        ++unsolicited_acks_;
        return false;
    }
    outstanding_bytes_ -= outstanding_.front().bytes;
    outstanding_.pop_front();
    ++acknowledged_;
    resends_of_oldest_ = 0;
    if (failed_) return false;
    // Progress: the next unanswered line (if any) gets a fresh timeout.
    if (!outstanding_.empty()) {
        arm_line_timeout();
    } else {
        ++timeout_generation_;  // nothing outstanding: no timeout pending
    }
    return true;
}

// --- sending -------------------------------------------------------------------

void UartHost::become_ready() {
    if (ready_ || failed_) return;
    ready_ = true;
    pump();
    check_finished();
}

void UartHost::pump() {
    if (!ready_ || failed_) return;
    while (next_ < lines_.size()) {
        const std::size_t bytes = lines_[next_].text.size() + 1;
        if (options_.flow == FlowControl::SendAndWait) {
            if (!outstanding_.empty()) break;
        } else {
            if (bytes > options_.rx_buffer_bytes) {
                const GcodeLine& line = lines_[next_];
                HostEvent e;
                e.kind = HostEventKind::LineTooLong;
                e.cycle = mcu_.cycle();
                e.line = line;
                e.message = "line " + std::to_string(line.number) + " " + quoted_line(line.text) + " is " +
                            std::to_string(bytes) + " bytes with its newline, more than the " +
                            std::to_string(options_.rx_buffer_bytes) + "-byte receive buffer";
                fail(std::move(e));
                return;
            }
            if (outstanding_bytes_ + bytes > options_.rx_buffer_bytes) break;
        }
        send_line(next_++);
    }
}

void UartHost::send_line(std::size_t index) {
    const GcodeLine& line = lines_[index];
    if (options_.family == FirmwareFamily::Grbl && (line.text == "?" || line.text == "!" || line.text == "~")) {
        // grbl's realtime commands are single bytes picked out of the stream:
        // not counted in its receive buffer, never answered with ok.
        transcript_.push_back(TranscriptEntry{mcu_.cycle(), Direction::Sent, line.text, line.number});
        uart_.send(line.text);
        ++acknowledged_;
        for (auto& fn : bytes_listeners_) fn(line.text);
        return;
    }
    const std::size_t bytes = line.text.size() + 1;
    const bool was_idle = outstanding_.empty();
    outstanding_.push_back(Outstanding{index, bytes});
    outstanding_bytes_ += bytes;
    if (outstanding_.size() > max_outstanding_lines_) max_outstanding_lines_ = outstanding_.size();
    if (outstanding_bytes_ > max_outstanding_bytes_) max_outstanding_bytes_ = outstanding_bytes_;
    transcript_.push_back(TranscriptEntry{mcu_.cycle(), Direction::Sent, line.text, line.number});
    uart_.send(line.text + "\n");
    for (auto& fn : sent_listeners_) fn(line);
    if (was_idle) {
        // The pause a keep-alive ends is counted from the later of the last
        // output and this line: the silence the line timeout measures.
        last_output_cycle_ = mcu_.cycle();
        arm_line_timeout();  // after queueing: the timeout counts from the line's last byte
    }
    if (was_idle && options_.family == FirmwareFamily::Grbl && options_.grbl_status_poll_s > 0) {
        poll_status(++poll_generation_);
    }
}

// The oldest unanswered line must be answered within line_timeout_s of the
// later of its sending and the previous answer: a firmware that is busy with
// earlier lines is not timed out while it keeps answering them.
void UartHost::arm_line_timeout() {
    const std::uint64_t generation = ++timeout_generation_;
    // The clock starts once the firmware has the whole line: bytes still
    // queued for its receiver (a long line at 115200 baud takes seconds).
    const Cycle still_sending = static_cast<Cycle>(uart_.pending_rx()) * uart_.cycles_per_frame();
    timeout_armed_cycle_ = mcu_.cycle() + still_sending;
    schedule_line_timeout(generation, timeout_armed_cycle_ + mcu_.cycles_from_seconds(timeout_for_oldest_s()));
}

void UartHost::schedule_line_timeout(std::uint64_t generation, Cycle at) {
    std::weak_ptr<bool> alive = alive_;
    mcu_.scheduler().at(std::max(at, mcu_.cycle() + 1), [this, alive, generation](Cycle) {
        if (alive.expired() || generation != timeout_generation_) return;
        // The machine stepped since the timeout started: the firmware is at
        // work on it; count again from its last step.
        if (activity_probe_) {
            if (const std::optional<Cycle> last = activity_probe_(); last && *last > timeout_armed_cycle_) {
                timeout_armed_cycle_ = *last;
                schedule_line_timeout(generation, *last + mcu_.cycles_from_seconds(timeout_for_oldest_s()));
                return;
            }
        }
        on_line_timeout();
    });
}

// After the welcome, the first line goes out once the firmware has been
// quiet for quiet_after_welcome_s: each line of boot chatter starts it again.
void UartHost::arm_quiet_timer() {
    const std::uint64_t generation = ++quiet_generation_;
    std::weak_ptr<bool> alive = alive_;
    mcu_.scheduler().after(mcu_.cycles_from_seconds(options_.quiet_after_welcome_s), [this, alive, generation](Cycle) {
        if (alive.expired() || generation != quiet_generation_) return;
        become_ready();
    });
}

// Marlin asks for a line again ("Resend: N" after "Error:checksum mismatch"
// or a line-number mismatch) and then says "ok": that "ok" means "ready",
// not "done". The host sends its oldest unanswered line again on that ok
// (as Printrun does); the resent line gets an ok of its own.
void UartHost::resend(Cycle cycle, const std::string& text) {
    ++resends_;
    if (outstanding_.empty()) return;
    // A line the firmware rejects every time (a bad checksum of its own,
    // a `*` with nothing before it) would be resent forever: give up after
    // this many in a row (assumed: a host's patience, as OctoPrint warns
    // about resend storms; Printrun has no limit).
    constexpr std::size_t kMaxResendsOfOneLine = 5;
    if (++resends_of_oldest_ > kMaxResendsOfOneLine) {
        HostEvent e = event_at_oldest_line(HostEventKind::ResendLoop, cycle, text);
        e.message = "line " + std::to_string(e.line->number) + " " + quoted_line(e.line->text) + " was asked for again " +
                    std::to_string(kMaxResendsOfOneLine) + " times in a row ('" + text + "'): the firmware rejects it every time";
        fail(std::move(e));
        return;
    }
    resend_on_next_ok_ = true;
}

double UartHost::line_timeout_s() const {
    constexpr double kKeepaliveMargin = 2.5;  // as default_line_timeout_s
    return std::max(options_.line_timeout_s, kKeepaliveMargin * keepalive_pause_s_);
}

// The timeout for the oldest unanswered line: longer for commands that take
// long by design.
double UartHost::timeout_for_oldest_s() const {
    const double line_timeout = line_timeout_s();
    if (outstanding_.empty()) return line_timeout;
    const GcodeLine& line = lines_[outstanding_.front().index];
    const std::vector<GcodeWord> words = lex_lenient_gcode(line.text);
    const auto has_word = [&words](char letter, double code) {
        return std::any_of(words.begin(), words.end(), [&](const GcodeWord& w) { return w.letter == letter && w.value == code; });
    };
    if (has_word('G', 4)) {
        // Dwell: P in seconds on grbl (its G-code reference follows
        // LinuxCNC), in milliseconds on Marlin and Teacup (S in seconds).
        // grbl and Marlin first wait for every queued move to finish, so G4
        // is a long command whatever its dwell.
        double dwell_s = 0;
        const double p_unit_s = options_.family == FirmwareFamily::Grbl ? 1.0 : 1e-3;
        if (const GcodeWord* p = find_word(words, 'P')) dwell_s = p->value * p_unit_s;
        else if (const GcodeWord* sec = find_word(words, 'S')) dwell_s = sec->value;
        if (!std::isfinite(dwell_s) || dwell_s < 0) dwell_s = 0;
        return std::max(options_.long_command_timeout_s, std::min(dwell_s, 1e6) + line_timeout);
    }
    const bool homing_cycle = line.text.size() >= 2 && line.text[0] == '$' && (line.text[1] == 'H' || line.text[1] == 'h');  // grbl's $H
    if (homing_cycle || has_word('M', 109) || has_word('M', 190) || has_word('M', 116) || has_word('G', 28) || has_word('G', 29)) {
        return std::max(options_.long_command_timeout_s, line_timeout);
    }
    return line_timeout;
}

// While lines are unanswered, a '?' every grbl_status_poll_s: the report it
// brings back is the keep-alive that restarts the timeouts.
void UartHost::poll_status(std::uint64_t generation) {
    std::weak_ptr<bool> alive = alive_;
    mcu_.scheduler().after(mcu_.cycles_from_seconds(options_.grbl_status_poll_s), [this, alive, generation](Cycle) {
        if (alive.expired() || generation != poll_generation_ || failed_ || outstanding_.empty()) return;
        uart_.send("?");
        ++status_polls_;
        poll_status(generation);
    });
}

void UartHost::on_line_timeout() {
    if (failed_ || outstanding_.empty()) return;
    const GcodeLine& line = lines_[outstanding_.front().index];
    HostEvent e;
    e.kind = HostEventKind::Timeout;
    e.cycle = mcu_.cycle();
    e.line = line;
    e.message = "line " + std::to_string(line.number) + " " + quoted_line(line.text) + " got no answer within " +
                seconds_text(timeout_for_oldest_s());
    fail(std::move(e));
}

void UartHost::record(HostEvent event) { events_.record(std::move(event)); }

void UartHost::fail(HostEvent event) {
    if (failed_) {
        record(std::move(event));
        return;
    }
    failed_ = true;
    ++timeout_generation_;  // no timeout after the stop
    failure_event_ = events_.size();
    record(std::move(event));
    check_finished();
}

void UartHost::check_finished() {
    if (stop_mcu_when_finished_ && finished()) mcu_.request_stop();
}

bool UartHost::run_until_finished(double max_seconds) {
    const Cycle target = mcu_.cycle() + mcu_.cycles_from_seconds(max_seconds);
    stop_mcu_when_finished_ = true;
    while (!finished() && mcu_.cycle() < target) {
        if (mcu_.run_until(target) == StopReason::Halted) break;
    }
    stop_mcu_when_finished_ = false;
    return finished();
}

// --- transcript -----------------------------------------------------------------

std::string UartHost::seconds_text(double seconds) const {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g s", seconds);
    return buf;
}

std::string UartHost::tail(std::size_t n) const {
    std::string out;
    const std::size_t first = transcript_.size() > n ? transcript_.size() - n : 0;
    for (std::size_t i = first; i < transcript_.size(); ++i) {
        const auto& e = transcript_[i];
        char stamp[48];
        std::snprintf(stamp, sizeof stamp, "%12.6f s %c ",
                      static_cast<double>(e.cycle) / static_cast<double>(mcu_.frequency_hz()),
                      e.direction == Direction::Sent ? '>' : '<');
        out += stamp;
        out += e.text.size() > 200 ? quoted_line(e.text) : printable(e.text);
        out += '\n';
    }
    return out;
}

}  // namespace avrbench
