#include "trace/Timeline.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace avrbench {

namespace {

bool has_whitespace(const std::string& text) {
    return std::any_of(text.begin(), text.end(),
                       [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; });
}

std::string describe(const SignalInfo& info) { return "signal '" + info.scope + "." + info.name + "'"; }

}  // namespace

SignalId Timeline::add_signal(SignalInfo info) {
    // Checked here, at registration, so a bad signal fails where it is declared
    // rather than much later when a writer produces a file a viewer rejects.
    if (info.scope.empty() || info.name.empty())
        throw std::invalid_argument(describe(info) + ": scope and name must not be empty");
    if (has_whitespace(info.scope) || has_whitespace(info.name))
        throw std::invalid_argument(describe(info) + ": scope and name must not contain whitespace");
    if (info.clock_hz == 0) throw std::invalid_argument(describe(info) + ": clock_hz must not be 0");
    switch (info.kind) {
    case SignalKind::Wire:
        if (info.width != 1)
            throw std::invalid_argument(describe(info) + ": a Wire is 1 bit wide, got width " +
                                        std::to_string(info.width));
        break;
    case SignalKind::Bus:
        if (info.width < 1 || info.width > 64)
            throw std::invalid_argument(describe(info) + ": Bus width must be 1..64, got " +
                                        std::to_string(info.width));
        break;
    case SignalKind::Real:
        info.width = 64;  // VCD declares reals as 64-bit; the field is otherwise unused
        break;
    }
    const auto id = static_cast<SignalId>(signals_.size());
    if (!index_.emplace(std::make_pair(info.scope, info.name), id).second)
        throw std::invalid_argument(describe(info) + " is already registered");
    signals_.push_back(std::move(info));
    return id;
}

void Timeline::add_alias(SignalId target, const std::string& scope, const std::string& name) {
    if (target >= signals_.size()) throw std::invalid_argument("alias " + scope + "." + name + ": no such signal");
    if (scope.empty() || name.empty() || has_whitespace(scope) || has_whitespace(name)) {
        throw std::invalid_argument("alias '" + scope + "." + name + "': scope and name must be non-empty, without whitespace");
    }
    if (!index_.emplace(std::make_pair(scope, name), target).second) {
        throw std::invalid_argument("alias " + scope + "." + name + ": the name is already used");
    }
    aliases_.push_back({target, scope, name});
}

long Timeline::find(const std::string& scope, const std::string& name) const {
    const auto it = index_.find(std::make_pair(scope, name));
    return it == index_.end() ? -1 : static_cast<long>(it->second);
}

void Timeline::stream_to(EventSink sink, std::size_t batch_events) {
    if (!keep_.empty()) throw std::invalid_argument("a timeline that keeps signals when taken cannot stream to a sink");
    sink_ = std::move(sink);
    sink_batch_ = std::max<std::size_t>(1, batch_events);
    limit_ = sink_ ? sink_limit() : max_held_;
    flush_stream();
}

void Timeline::flush_stream() {
    if (!sink_ || events_.empty()) return;
    sink_(events_);
    taken_ += events_.size();
    events_.clear();
    limit_ = sink_limit();
}

bool Timeline::make_room() {
    if (!sink_ || taken_ + events_.size() >= max_held_) {
        ++dropped_;
        return false;
    }
    flush_stream();
    return true;
}

std::string Timeline::overflow_message() const {
    return "the run recorded more than " + std::to_string(max_held_) +
           " signal changes, the most a comparison or report keeps in memory; " + std::to_string(dropped_) +
           " were dropped (shorten the run, trace fewer signals, or use run --vcd without --report, which streams)";
}

}  // namespace avrbench
