#include "trace/VcdWriter.hpp"

#include "core/Errors.hpp"
#include "core/OutputFile.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "trace/ScopeGroups.hpp"
#include "trace/VcdTimescale.hpp"

#ifndef AVRBENCH_VERSION
#define AVRBENCH_VERSION "dev"
#endif

namespace avrbench {

namespace {

// Text is formatted into one string and handed to fwrite in large blocks: per-
// character stream output would make a 10-million-event dump take minutes.
constexpr std::size_t kFlushBytes = std::size_t{1} << 20;

class Output {
public:
    Output(std::string& buffer, std::FILE* file, const std::string& path)
        : buffer_(buffer), file_(file), path_(path) {}

    void text(std::string_view s) { buffer_.append(s); }
    void character(char c) { buffer_.push_back(c); }
    void number(std::uint64_t value) {
        char digits[24];
        const auto end = std::to_chars(digits, digits + sizeof digits, value).ptr;
        buffer_.append(digits, end);
    }
    void real(double value) {
        char digits[40];
        // Shortest text that parses back to the same double.
        const auto end = std::to_chars(digits, digits + sizeof digits, value).ptr;
        buffer_.append(digits, end);
    }
    void binary(std::uint64_t value, unsigned width) {
        const std::size_t at = buffer_.size();
        buffer_.resize(at + width);
        char* out = buffer_.data() + at;
        for (unsigned bit = width; bit-- > 0;) *out++ = static_cast<char>('0' + ((value >> bit) & 1U));
    }
    void maybe_flush() {
        if (file_ != nullptr && buffer_.size() >= kFlushBytes) flush();
    }
    void flush() {
        if (file_ == nullptr || buffer_.empty()) return;
        if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
            throw BadInput("VCD: " + path_ + ": write failed: " + std::strerror(errno));
        buffer_.clear();
    }

private:
    std::string& buffer_;
    std::FILE* file_;
    const std::string& path_;
};

// Per-signal writer state: how to format it, what was last written, and the
// value staged for the timestamp being assembled.
struct SignalState {
    // VCD identifiers: one per bit when the bus is written as bits (bit 0
    // first), else one; then the same again for every alias that has codes
    // of its own (VcdOptions::alias_codes), in alias order.
    std::vector<std::string> codes;
    bool as_bits = false;
    unsigned codes_per_copy() const { return as_bits ? width : 1; }
    std::size_t copies() const { return codes.size() / codes_per_copy(); }
    SignalKind kind = SignalKind::Wire;
    unsigned width = 1;
    std::uint64_t mask = 1;
    std::uint32_t clock_hz = 0;
    std::uint64_t units_per_cycle = 0;  // 0: not a whole number, convert with rounding
    bool known = false;                 // false until a value was written (shown as x)
    std::uint64_t written = 0;          // last written value (a double's bits for Real)
    std::uint64_t staged = 0;
    std::uint64_t staged_group = std::numeric_limits<std::uint64_t>::max();
};

class VcdEmitter {
public:
    VcdEmitter(const Timeline& timeline, const VcdOptions& options, Output& out)
        : timeline_(timeline), options_(options), out_(out), timescale_(choose_timescale(timeline, options)) {
        const auto& infos = timeline.signals();
        signals_.resize(infos.size());
        std::uint32_t next_code = 0;
        for (std::size_t id = 0; id < infos.size(); ++id) {
            SignalState& s = signals_[id];
            const SignalInfo& info = infos[id];
            s.kind = info.kind;
            s.width = info.kind == SignalKind::Bus ? info.width : 1;
            s.as_bits = options.buses == VcdBuses::Bits && s.kind == SignalKind::Bus && s.width > 1;
            for (unsigned i = 0; i < s.codes_per_copy(); ++i) s.codes.push_back(vcd_identifier(next_code++));
            s.mask = s.width >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << s.width) - 1;
            s.clock_hz = info.clock_hz;
            s.units_per_cycle = timescale_.units_per_cycle(info.clock_hz);
        }
        // Aliases: the target's codes, or codes of their own after every signal's.
        for (const auto& alias : timeline.aliases()) {
            SignalState& s = signals_.at(alias.target);
            if (!options.alias_codes) {
                alias_copy_.push_back(0);
                continue;
            }
            alias_copy_.push_back(s.copies());
            for (unsigned i = 0; i < s.codes_per_copy(); ++i) s.codes.push_back(vcd_identifier(next_code++));
        }
    }

    VcdResult run() {
        begin();
        const auto& events = timeline_.events();
        bool sorted = true;
        std::uint64_t previous = 0;
        for (std::size_t i = 0; i < events.size() && sorted; ++i) {
            const std::uint64_t t = time_of(events[i], i);
            sorted = t >= previous;
            previous = t;
        }
        if (sorted) {
            // The common case (one MCU, or domains recorded in order): no copy, no sort.
            for (std::size_t i = 0; i < events.size(); ++i) feed(events[i], time_of(events[i], i));
        } else {
            // Sorting (time, record index) pairs is the stable sort by time.
            std::vector<Keyed> keys(events.size());
            for (std::size_t i = 0; i < events.size(); ++i) keys[i] = Keyed{time_of(events[i], i), i};
            std::sort(keys.begin(), keys.end(), [](const Keyed& a, const Keyed& b) {
                return a.time != b.time ? a.time < b.time : a.index < b.index;
            });
            for (const Keyed& k : keys) feed(events[k.index], k.time);
        }
        return end();
    }

    void begin() { write_header(); }

    // The next event in time order (time from time_of). Events at time 0 give
    // the $dumpvars values; a timestamp is written once all its events are in.
    void feed(const TimelineEvent& e, std::uint64_t time) {
        if (!dumped_) {
            if (time == 0) {
                stage(e);
                return;
            }
            write_dumpvars();
        }
        if (have_current_ && time != current_) {
            if (time < current_) {
                throw std::logic_error("VCD: an event at time " + std::to_string(time) + " arrived after time " +
                                       std::to_string(current_) + " was written");
            }
            commit(current_);
        }
        current_ = time;
        have_current_ = true;
        stage(e);
    }

    VcdResult end() {
        if (!dumped_) write_dumpvars();
        if (have_current_) commit(current_);
        have_current_ = false;
        const VcdOptions& end_options = end_options_ ? *end_options_ : options_;
        if (end_options.end_cycle) {
            const std::uint64_t end_time = timescale_.units_at(*end_options.end_cycle, end_options.end_clock_hz);
            if (end_time > result_.end_time) {
                out_.character('#');
                out_.number(end_time);
                out_.character('\n');
                result_.end_time = end_time;
            }
        }
        out_.flush();
        result_.timescale = timescale_.text();
        result_.exact = timescale_.exact();
        return result_;
    }

    const VcdTimescale& timescale() const { return timescale_; }
    void set_end(const VcdOptions& options) { end_options_ = options; }
    std::uint64_t time_of(const TimelineEvent& e, std::size_t index) const {
        if (e.signal >= signals_.size())
            throw std::out_of_range("timeline event " + std::to_string(index) + " refers to signal id " +
                                    std::to_string(e.signal) + ", but only " + std::to_string(signals_.size()) +
                                    " signals are registered");
        const SignalState& s = signals_[e.signal];
        std::uint64_t units = 0;
        if (s.units_per_cycle != 0 && !__builtin_mul_overflow(e.cycle, s.units_per_cycle, &units)) return units;
        return timescale_.units_at(e.cycle, s.clock_hz);  // rounds, or throws on overflow
    }

private:
    struct Keyed {
        std::uint64_t time;
        std::size_t index;
    };

    static VcdTimescale choose_timescale(const Timeline& timeline, const VcdOptions& options) {
        std::vector<std::uint32_t> clocks;
        for (const SignalInfo& info : timeline.signals()) clocks.push_back(info.clock_hz);
        if (options.end_cycle) clocks.push_back(options.end_clock_hz);
        return VcdTimescale::for_clocks(clocks);
    }

    std::uint64_t normalized(const SignalState& s, const TimelineEvent& e) const {
        switch (s.kind) {
        case SignalKind::Wire: return e.value.bits != 0 ? 1 : 0;
        case SignalKind::Bus: return e.value.bits & s.mask;
        case SignalKind::Real: return std::bit_cast<std::uint64_t>(e.value.real);
        }
        return 0;
    }

    void write_header() {
        out_.text("$version avrbench " AVRBENCH_VERSION " $end\n");
        // No $date: the dump must not depend on when it was written.
        out_.text("$comment cycle times:");
        std::vector<std::uint32_t> clocks;
        for (const SignalState& s : signals_) clocks.push_back(s.clock_hz);
        if (options_.end_cycle) clocks.push_back(options_.end_clock_hz);
        std::sort(clocks.begin(), clocks.end());
        clocks.erase(std::unique(clocks.begin(), clocks.end()), clocks.end());
        for (const std::uint32_t clock_hz : clocks) {
            out_.text(" ");
            out_.number(clock_hz);
            const std::uint64_t per_cycle = timescale_.units_per_cycle(clock_hz);
            out_.text(" Hz: ");
            if (per_cycle != 0) {
                out_.number(per_cycle);
                out_.text(" x ");
                out_.text(timescale_.text());
                out_.text(" per cycle, exact;");
            } else {
                out_.text("rounded to the nearest ");
                out_.text(timescale_.text());
                out_.text(";");
            }
        }
        out_.text(" $end\n");
        out_.text("$timescale ");
        out_.text(timescale_.text());
        out_.text(" $end\n");

        const auto& infos = timeline_.signals();
        auto declare = [&](SignalId id, const std::string& name, std::size_t copy) {
            const SignalState& s = signals_[id];
            const std::string* codes = &s.codes[copy * s.codes_per_copy()];
            if (s.as_bits) {
                // MSB first, as a vector's bits read; "name[i]" with no space, so
                // every bit is a signal of its own name in every reader.
                for (unsigned bit = s.width; bit-- > 0;) {
                    out_.text("$var wire 1 ");
                    out_.text(codes[bit]);
                    out_.character(' ');
                    out_.text(name);
                    out_.character('[');
                    out_.number(bit);
                    out_.text("] $end\n");
                }
                return;
            }
            out_.text(s.kind == SignalKind::Real ? "$var real 64 " : "$var wire ");
            if (s.kind != SignalKind::Real) {
                out_.number(s.width);
                out_.character(' ');
            }
            out_.text(codes[0]);
            out_.character(' ');
            out_.text(name);
            out_.text(" $end\n");
        };
        // Signals by scope, then aliases (same identifier code as their target)
        // in their scope: a scope is one $scope block whoever declared it.
        std::vector<ScopeGroup> groups = group_by_scope(timeline_);
        for (const auto& alias : timeline_.aliases()) {
            if (std::none_of(groups.begin(), groups.end(), [&](const ScopeGroup& g) { return g.scope == alias.scope; })) {
                groups.push_back(ScopeGroup{alias.scope, {}});
            }
        }
        for (const ScopeGroup& group : groups) {
            out_.text("$scope module ");
            out_.text(group.scope);
            out_.text(" $end\n");
            for (const SignalId id : group.signals) declare(id, infos[id].name, 0);
            const auto& aliases = timeline_.aliases();
            for (std::size_t a = 0; a < aliases.size(); ++a) {
                if (aliases[a].scope == group.scope) declare(aliases[a].target, aliases[a].name, alias_copy_[a]);
            }
            out_.text("$upscope $end\n");
        }
        out_.text("$enddefinitions $end\n");
    }

    // `previous` and `known`: what was written before, so a bus written as
    // bits writes only the bits that changed. Every copy (aliases with codes
    // of their own) gets the same change.
    void write_value(const SignalState& s, std::uint64_t value, std::uint64_t previous = 0, bool known = false) {
        const unsigned per_copy = s.codes_per_copy();
        for (std::size_t copy = 0; copy < s.copies(); ++copy) {
            const std::string* codes = &s.codes[copy * per_copy];
            if (s.as_bits) {
                const std::uint64_t changed = known ? (value ^ previous) & s.mask : s.mask;
                for (unsigned bit = s.width; bit-- > 0;) {
                    if (((changed >> bit) & 1U) == 0) continue;
                    out_.character(((value >> bit) & 1U) != 0 ? '1' : '0');
                    out_.text(codes[bit]);
                    out_.character('\n');
                }
                continue;
            }
            if (s.kind == SignalKind::Real) {
                out_.character('r');
                out_.real(std::bit_cast<double>(value));
                out_.character(' ');
            } else if (s.width == 1) {
                out_.character(value != 0 ? '1' : '0');
            } else {
                out_.character('b');
                out_.binary(value, s.width);
                out_.character(' ');
            }
            out_.text(codes[0]);
            out_.character('\n');
        }
    }

    void write_unknown(const SignalState& s) {
        const unsigned per_copy = s.codes_per_copy();
        for (std::size_t i = 0; i < s.codes.size(); ++i) {
            // MSB first within each copy, as write_value writes bits.
            const std::string& code = s.codes[(i / per_copy) * per_copy + (per_copy - 1 - i % per_copy)];
            if (s.as_bits || (s.kind == SignalKind::Bus && s.width == 1))
                out_.character('z');
            else if (s.kind == SignalKind::Real)
                out_.text("r0 ");
            else if (s.kind == SignalKind::Bus)
                out_.text("bz ");
            else
                out_.character('x');
            out_.text(code);
            out_.character('\n');
        }
    }

    void stage(const TimelineEvent& e) {
        SignalState& s = signals_[e.signal];
        if (s.staged_group != group_) {
            s.staged_group = group_;
            touched_.push_back(e.signal);
        }
        s.staged = normalized(s, e);  // a later event at the same time overrides
    }

    // Writes the staged values of one timestamp that differ from what was written.
    void commit(std::uint64_t time) {
        bool stamped = false;
        for (const SignalId id : touched_) {
            SignalState& s = signals_[id];
            if (s.known && s.staged == s.written) continue;
            if (!stamped) {
                out_.character('#');
                out_.number(time);
                out_.character('\n');
                stamped = true;
                result_.end_time = time;
            }
            write_value(s, s.staged, s.written, s.known);
            s.written = s.staged;
            s.known = true;
            ++result_.value_changes;
        }
        touched_.clear();
        ++group_;
        out_.maybe_flush();
    }

    void write_dumpvars() {
        out_.text("#0\n$dumpvars\n");
        for (SignalState& s : signals_) {
            if (s.staged_group == group_) {
                write_value(s, s.staged);
                s.written = s.staged;
            } else {
                write_unknown(s);
                s.written = 0;  // r0 for a real; unused for x
            }
            s.known = s.kind == SignalKind::Real || s.staged_group == group_;
        }
        out_.text("$end\n");
        touched_.clear();
        ++group_;
        dumped_ = true;
    }

    const Timeline& timeline_;
    const VcdOptions& options_;
    Output& out_;
    VcdTimescale timescale_;
    std::vector<SignalState> signals_;
    std::vector<std::size_t> alias_copy_;  // per alias: which copy of its target's codes it declares
    std::vector<SignalId> touched_;
    std::uint64_t group_ = 0;  // counts timestamps; marks which signals are staged
    std::optional<VcdOptions> end_options_;  // a stream learns its end only at the end
    bool dumped_ = false;      // $dumpvars written
    bool have_current_ = false;
    std::uint64_t current_ = 0;  // the timestamp being assembled
    VcdResult result_;
};

}  // namespace

std::string vcd_identifier(std::uint32_t index) {
    // Bijective numeration (no "zero digit" problem): every code is distinct and
    // as short as possible. A code made of 4+ digits could spell a keyword such
    // as "$end"; that takes over 839,000 signals, far beyond any bench.
    std::string code;
    std::uint64_t n = index;
    for (;;) {
        code.push_back(static_cast<char>('!' + n % 94));
        n /= 94;
        if (n == 0) break;
        --n;
    }
    return code;
}

std::string format_vcd(const Timeline& timeline, const VcdOptions& options, VcdResult* result) {
    std::string text;
    const std::string no_path;
    Output out(text, nullptr, no_path);
    const VcdResult written = VcdEmitter(timeline, options, out).run();
    if (result != nullptr) *result = written;
    return text;
}

struct VcdStream::Impl {
    struct Held {
        std::uint64_t time;
        std::uint64_t sequence;
        TimelineEvent event;
    };
    Impl(const Timeline& timeline, const std::string& path, const VcdOptions& layout)
        : no_options{layout.buses, layout.alias_codes, std::nullopt, 16000000}, file(path, "VCD"), path_copy(path), out(buffer, file.stream(), path_copy), emitter(timeline, no_options, out) {
        buffer.reserve(kFlushBytes + 4096);
        emitter.begin();
    }
    void take(Timeline& timeline) {
        timeline.take_events_into(taken);
        for (const TimelineEvent& e : taken) {
            held.push_back(Held{emitter.time_of(e, static_cast<std::size_t>(sequence)), sequence, e});
            ++sequence;
        }
    }
    void write_up_to(std::uint64_t limit) {
        // Held events in recording order; those due go out sorted by (time,
        // recording order), the rest stay in recording order.
        due.clear();
        std::size_t kept = 0;
        for (const Held& h : held) {
            if (h.time <= limit) {
                due.push_back(h);
            } else {
                held[kept++] = h;
            }
        }
        held.resize(kept);
        std::stable_sort(due.begin(), due.end(), [](const Held& a, const Held& b) { return a.time < b.time; });
        for (const Held& h : due) emitter.feed(h.event, h.time);
        out.maybe_flush();
    }

    VcdOptions no_options;
    OutputFile file;
    std::string path_copy;
    std::string buffer;
    Output out;
    VcdEmitter emitter;
    std::vector<Held> held;
    std::vector<Held> due;            // reused: a drain every 10 ms allocates nothing
    std::vector<TimelineEvent> taken;  // reused, swapped with the timeline's buffer
    std::uint64_t sequence = 0;
};

VcdStream::VcdStream(const Timeline& timeline, const std::string& path, const VcdOptions& layout)
    : impl_(std::make_unique<Impl>(timeline, path, layout)) {}

VcdStream::~VcdStream() = default;

void VcdStream::drain(Timeline& timeline, Picoseconds settled_ps) {
    impl_->take(timeline);
    __extension__ typedef unsigned __int128 WideUnits;  // ps x units/s passes 2^64 after 18.4 ms at 1 ns
    const WideUnits units = static_cast<WideUnits>(settled_ps) *
                                    impl_->emitter.timescale().units_per_second() / kPsPerSecond;
    impl_->write_up_to(units > std::numeric_limits<std::uint64_t>::max() ? std::numeric_limits<std::uint64_t>::max()
                                                                          : static_cast<std::uint64_t>(units));
}

VcdResult VcdStream::finish(Timeline& timeline, const VcdOptions& options) {
    impl_->take(timeline);
    impl_->write_up_to(std::numeric_limits<std::uint64_t>::max());
    impl_->emitter.set_end(options);
    const VcdResult result = impl_->emitter.end();
    impl_->file.commit();
    return result;
}

std::size_t VcdStream::held_events() const { return impl_->held.size(); }

VcdResult write_vcd(const Timeline& timeline, const std::string& path, const VcdOptions& options) {
    // Written beside the target and renamed into place when complete: a
    // failed write leaves whatever was at `path` untouched (core/OutputFile).
    OutputFile file(path, "VCD");
    std::string buffer;
    buffer.reserve(kFlushBytes + 4096);
    Output out(buffer, file.stream(), path);
    const VcdResult result = VcdEmitter(timeline, options, out).run();
    file.commit();
    return result;
}

}  // namespace avrbench
