#include "trace/html/ReportParts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

namespace avrbench::html_report {

double event_value(const SignalInfo& info, const TimelineEvent& e) {
    switch (info.kind) {
    case SignalKind::Real: return e.value.real;
    case SignalKind::Wire: return e.value.bits != 0 ? 1.0 : 0.0;
    case SignalKind::Bus: {
        const std::uint64_t mask = info.width >= 64 ? ~0ULL : ((1ULL << info.width) - 1);
        return static_cast<double>(e.value.bits & mask);
    }
    }
    return 0.0;
}

void normalize(Series& s) {
    if (!std::is_sorted(s.begin(), s.end(), [](const Sample& a, const Sample& b) { return a.t < b.t; }))
        std::stable_sort(s.begin(), s.end(), [](const Sample& a, const Sample& b) { return a.t < b.t; });
    Series out;
    out.reserve(s.size());
    for (const Sample& x : s) {
        if (!std::isfinite(x.v)) continue;
        if (!out.empty() && out.back().t == x.t) {
            out.back().v = x.v;
            if (out.size() >= 2 && out[out.size() - 2].v == x.v) out.pop_back();
            continue;
        }
        if (!out.empty() && out.back().v == x.v) continue;
        out.push_back(x);
    }
    s = std::move(out);
}

std::vector<Series> extract(const Timeline& timeline, const std::vector<SignalId>& ids) {
    const auto& signals = timeline.signals();
    std::vector<int> slot(signals.size(), -1);
    std::vector<Series> unique;
    std::vector<SignalId> unique_ids;
    std::vector<std::size_t> which(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) {
        if (ids[i] >= signals.size())
            throw std::out_of_range("HTML report: signal id " + std::to_string(ids[i]) +
                                    " is not in the timeline (" + std::to_string(signals.size()) + " signals)");
        if (slot[ids[i]] < 0) {
            slot[ids[i]] = static_cast<int>(unique.size());
            unique.emplace_back();
            unique_ids.push_back(ids[i]);
        }
        which[i] = static_cast<std::size_t>(slot[ids[i]]);
    }
    if (!unique.empty()) {
        for (const TimelineEvent& e : timeline.events()) {
            if (e.signal >= slot.size()) continue;
            const int s = slot[e.signal];
            if (s < 0) continue;
            const SignalInfo& info = signals[e.signal];
            unique[static_cast<std::size_t>(s)].push_back({to_seconds(e.cycle, info.clock_hz), event_value(info, e)});
        }
    }
    for (Series& s : unique) normalize(s);
    std::vector<Series> out;
    out.reserve(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) out.push_back(unique[which[i]]);
    return out;
}

double last_time(const std::vector<Series>& all) {
    double t = 0;
    for (const Series& s : all)
        if (!s.empty()) t = std::max(t, s.back().t);
    return t;
}

long find_signal(const Timeline& timeline, const std::string& full_name) {
    const auto& signals = timeline.signals();
    for (std::size_t i = 0; i < signals.size(); ++i)
        if (signals[i].scope + "." + signals[i].name == full_name) return static_cast<long>(i);
    return -1;
}

DataPoints step_points(const Series& s, double t0, double t1, int columns) {
    DataPoints out;
    if (s.empty() || t1 <= t0) return out;
    auto first_after = std::upper_bound(s.begin(), s.end(), t0, [](double t, const Sample& x) { return t < x.t; });
    auto end = std::upper_bound(s.begin(), s.end(), t1, [](double t, const Sample& x) { return t < x.t; });
    double current;
    if (first_after != s.begin()) {
        current = std::prev(first_after)->v;
        out.emplace_back(t0, current);
    } else {
        if (first_after == end) return out;  // starts after the window
        current = first_after->v;
        out.emplace_back(first_after->t, current);
        ++first_after;
    }
    const auto count = static_cast<std::size_t>(end - first_after);
    if (count <= static_cast<std::size_t>(columns)) {
        for (auto it = first_after; it != end; ++it) {
            out.emplace_back(it->t, current);
            out.emplace_back(it->t, it->v);
            current = it->v;
        }
    } else {
        const double w = (t1 - t0) / columns;
        auto it = first_after;
        // One function decides an event's column, so each pass takes at least one event.
        auto column_of = [&](double t) { return std::clamp(static_cast<long>((t - t0) / w), 0L, static_cast<long>(columns - 1)); };
        while (it != end) {
            const long c = column_of(it->t);
            const double col_end = t0 + static_cast<double>(c + 1) * w;
            const double x_left = t0 + static_cast<double>(c) * w;
            const double x_mid = x_left + w / 2;
            double lo = current, hi = current;
            std::size_t lo_at = 0, hi_at = 0, k = 0;
            const double enter = current;
            for (; it != end && column_of(it->t) == c; ++it) {
                ++k;
                if (it->v < lo) lo = it->v, lo_at = k;
                if (it->v > hi) hi = it->v, hi_at = k;
                current = it->v;
            }
            out.emplace_back(x_left, enter);
            if (lo_at <= hi_at) {
                out.emplace_back(x_mid, lo);
                out.emplace_back(x_mid, hi);
            } else {
                out.emplace_back(x_mid, hi);
                out.emplace_back(x_mid, lo);
            }
            out.emplace_back(std::min(col_end, t1), current);
        }
    }
    out.emplace_back(t1, current);
    return out;
}

DataPoints mean_points(const Series& s, double t0, double t1, int columns) {
    const auto inside = std::count_if(s.begin(), s.end(), [&](const Sample& x) { return x.t > t0 && x.t <= t1; });
    if (inside <= columns) return step_points(s, t0, t1, columns);
    DataPoints out;
    const double w = (t1 - t0) / columns;
    // The value before the first sample is taken as the first sample's.
    std::size_t i = 0;
    double current = s.front().v;
    while (i < s.size() && s[i].t <= t0) current = s[i++].v;
    for (int c = 0; c < columns; ++c) {
        const double c0 = t0 + static_cast<double>(c) * w, c1 = c0 + w;
        double area = 0, at = c0;
        while (i < s.size() && s[i].t < c1) {
            area += current * (s[i].t - at);
            at = s[i].t;
            current = s[i++].v;
        }
        area += current * (c1 - at);
        out.emplace_back(c0 + w / 2, area / w);
    }
    return out;
}

Series windowed_velocity(const Series& position, double t0, double t1, int columns, double min_window_s) {
    Series out;
    if (position.size() < 2 || t1 <= t0 || columns <= 0) return out;
    const double column_s = (t1 - t0) / columns;
    const double window_s = std::max(4 * column_s, min_window_s);
    auto first_at_or_after = [&position](double t) {
        return std::lower_bound(position.begin(), position.end(), t,
                                [](const Sample& s, double at) { return s.t < at; });
    };
    for (int c = 0; c < columns; ++c) {
        const double centre = t0 + (c + 0.5) * column_s;
        // The first sample is where the axis starts, not a change.
        const auto begin = std::max(first_at_or_after(centre - window_s / 2), position.begin() + 1);
        const auto end = first_at_or_after(centre + window_s / 2);
        // Edge to edge: the position changes inside the window and the time
        // between the first and the last of them. A steady step rate gives
        // exactly its velocity, however the window falls on the steps; the
        // quiet before a move's first step or after its last does not dilute it.
        double v = 0;
        if (end > begin && end - begin >= 2) {
            const Sample& first = *begin;
            const Sample& last = *(end - 1);
            if (last.t > first.t) v = (last.v - first.v) / (last.t - first.t);
        }
        out.push_back({t0 + c * column_s, v});
    }
    out.push_back({t1, out.back().v});
    normalize(out);
    return out;
}

}  // namespace avrbench::html_report
