#include "trace/HtmlReport.hpp"

#include "core/OutputFile.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

namespace avrbench {

using namespace html_report;

namespace html_report {

std::string id_fragment(const std::string& name) {
    std::string out = name;
    for (char& c : out) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
        if (!ok) c = '-';
    }
    return out;
}

}  // namespace html_report

namespace {

constexpr std::size_t kNoLimit = std::numeric_limits<std::size_t>::max();

// Series colours (colour-blind friendly enough, distinct on white).
constexpr std::array<const char*, 8> kPalette = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                                 "#9467bd", "#8c564b", "#e377c2", "#17becf"};
const char* palette(std::size_t i) { return kPalette[i % kPalette.size()]; }
constexpr const char* kFaultColor = "#e66100";

constexpr const char* kToolpathColor = "#1f77b4";
constexpr const char* kGoldenColor = "#8fbce6";
constexpr const char* kActualColor = "#1d2330";
constexpr const char* kDivergenceColor = "#d62728";

// ---------------------------------------------------------------- text

void append_hex_escape(std::string& out, unsigned char c) {
    static const char* digits = "0123456789abcdef";
    out += "\\x";
    out += digits[c >> 4];
    out += digits[c & 15];
}

// Length of the valid UTF-8 sequence at text[i], or 0 when it is not one.
std::size_t utf8_sequence(std::string_view text, std::size_t i) {
    const auto b0 = static_cast<unsigned char>(text[i]);
    std::size_t len = 0;
    unsigned char lo = 0x80, hi = 0xbf;  // allowed range of the second byte
    if (b0 >= 0xc2 && b0 <= 0xdf) len = 2;
    else if (b0 >= 0xe0 && b0 <= 0xef) {
        len = 3;
        if (b0 == 0xe0) lo = 0xa0;
        if (b0 == 0xed) hi = 0x9f;  // no surrogates
    } else if (b0 >= 0xf0 && b0 <= 0xf4) {
        len = 4;
        if (b0 == 0xf0) lo = 0x90;
        if (b0 == 0xf4) hi = 0x8f;
    } else
        return 0;
    if (i + len > text.size()) return 0;
    for (std::size_t k = 1; k < len; ++k) {
        const auto b = static_cast<unsigned char>(text[i + k]);
        const unsigned char klo = k == 1 ? lo : 0x80, khi = k == 1 ? hi : 0xbf;
        if (b < klo || b > khi) return 0;
    }
    return len;
}

// HTML-escapes `text` onto `out`; control characters and bytes that are not
// valid UTF-8 become \xNN. At most `max_chars` characters are written, then
// an ellipsis. Returns true when it cut the text.
bool append_escaped(std::string& out, std::string_view text, std::size_t max_chars = kNoLimit) {
    std::size_t chars = 0;
    for (std::size_t i = 0; i < text.size();) {
        if (chars == max_chars) {
            out += "\xe2\x80\xa6";  // …
            return true;
        }
        const auto c = static_cast<unsigned char>(text[i]);
        ++chars;
        if (c < 0x80) {
            switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            case '\t': out += '\t'; break;
            default:
                if (c < 0x20 || c == 0x7f) append_hex_escape(out, c);
                else out += static_cast<char>(c);
            }
            ++i;
            continue;
        }
        const std::size_t len = utf8_sequence(text, i);
        if (len == 0) {
            append_hex_escape(out, c);
            ++i;
        } else {
            out.append(text.substr(i, len));
            i += len;
        }
    }
    return false;
}

std::string esc(std::string_view text) {
    std::string out;
    append_escaped(out, text);
    return out;
}

// Fixed-point with `decimals` digits, never "-0".
std::string fixed(double value, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
    std::string s = buf;
    if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
    return s;
}

// Shortest text that reads back to the same double (for data-* attributes).
std::string exact(double value) {
    char buf[64];
    for (int precision = 6; precision <= 17; ++precision) {
        std::snprintf(buf, sizeof buf, "%.*g", precision, value);
        if (std::strtod(buf, nullptr) == value) break;
    }
    return buf;
}

std::string seconds_text(double seconds) { return fixed(seconds, 6) + " s"; }

double to_seconds(Cycle cycle, std::uint32_t clock_hz) {
    return clock_hz == 0 ? 0.0 : static_cast<double>(cycle) / static_cast<double>(clock_hz);
}

// ---------------------------------------------------------------- series

struct Sample {
    double t;  // seconds
    double v;
};
using Series = std::vector<Sample>;

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

// Time order; at one time the last recorded value wins; repeats and values
// that are not finite are dropped.
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

// The series of each id, in one pass over the events.
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

// -1 when the timeline has no signal named "scope.name".
long find_signal(const Timeline& timeline, const std::string& full_name) {
    const auto& signals = timeline.signals();
    for (std::size_t i = 0; i < signals.size(); ++i)
        if (signals[i].scope + "." + signals[i].name == full_name) return static_cast<long>(i);
    return -1;
}

using DataPoints = std::vector<std::pair<double, double>>;

// A step function (the value holds until the next sample) over [t0, t1] as
// polyline points in data coordinates: exact when there is at most one change
// per column, else per column entering value, min and max in order, leaving value.
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

// A step function as its time average per column when it changes more than
// once per column (a PWM duty), else exactly as step_points draws it.
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

// Velocity as a step function of time, from the intervals between position
// changes: over (t[i-1], t[i]] the axis moved v[i] - v[i-1] in t[i] - t[i-1].
// A constant step rate gives a constant velocity whatever the plot's
// resolution (no aliasing against pixel columns). An interval over 4x longer
// than the next one is rest (a pause between moves, or the time from the
// start of the trace to a move's first step; an AVR446 ramp shortens its
// intervals by less than 2x per step). After the last change the axis
// stands still.
Series step_velocity(const Series& position) {
    Series out;
    if (position.size() < 2) return out;
    out.push_back({0, 0});
    for (std::size_t i = 1; i < position.size(); ++i) {
        const double dt = position[i].t - position[i - 1].t;
        if (dt <= 0) continue;
        const double next_dt = i + 1 < position.size() ? position[i + 1].t - position[i].t : dt;
        const bool pause = dt > 4 * next_dt;
        out.push_back({position[i - 1].t, pause ? 0.0 : (position[i].v - position[i - 1].v) / dt});
    }
    out.push_back({position.back().t, 0});
    normalize(out);
    return out;
}

// Average velocity per column of [t0, t1] (units per second); see the header.
[[maybe_unused]] std::vector<double> column_velocity(const Series& s, double t0, double t1, int columns) {
    std::vector<double> moved(static_cast<std::size_t>(columns), 0.0);
    if (s.size() < 2 || t1 <= t0) return moved;
    const double w = (t1 - t0) / columns;
    const double max_spread = 2 * w;
    auto column_of = [&](double t) {
        const double c = std::floor((t - t0) / w);
        return static_cast<long>(std::clamp(c, 0.0, static_cast<double>(columns - 1)));
    };
    for (std::size_t i = 1; i < s.size(); ++i) {
        const double delta = s[i].v - s[i - 1].v;
        const double dt = s[i].t - s[i - 1].t;
        const double next_dt = i + 1 < s.size() ? s[i + 1].t - s[i].t : dt;
        const double spread = std::min({dt, next_dt, max_spread});
        const double end = s[i].t;
        const double begin = end - spread;
        if (end <= t0 || begin >= t1) continue;
        if (spread <= 0) {
            moved[static_cast<std::size_t>(column_of(end))] += delta;
            continue;
        }
        for (long c = column_of(begin); c <= column_of(end); ++c) {
            const double c0 = t0 + static_cast<double>(c) * w, c1 = c0 + w;
            const double overlap = std::min(end, c1) - std::max(begin, c0);
            if (overlap > 0) moved[static_cast<std::size_t>(c)] += delta * overlap / spread;
        }
    }
    for (double& m : moved) m /= w;
    return moved;
}

// ---------------------------------------------------------------- scales and ticks

double nice_step(double range, double target) {
    if (!(range > 0)) return 1;
    const double raw = range / target;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double frac = raw / mag;
    const double nice = frac < 1.5 ? 1 : frac < 3 ? 2 : frac < 7 ? 5 : 10;
    return nice * mag;
}

int decimals_for(double step) {
    if (step >= 1) return 0;
    return std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
}

std::vector<double> tick_values(double lo, double hi, double step) {
    std::vector<double> out;
    const double k0 = std::ceil(lo / step - 1e-9), k1 = std::floor(hi / step + 1e-9);
    for (double k = k0; k <= k1 && out.size() < 100; k += 1) out.push_back(k * step);
    return out;
}

struct Range {
    double lo = 0, hi = 1, step = 0.2;
};

// A padded range with round ends, for a value axis.
Range nice_range(double lo, double hi, bool include_zero, double target = 5) {
    if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi) lo = 0, hi = 1;
    if (include_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
    if (hi - lo <= 1e-12 * std::max(1.0, std::fabs(hi))) {
        const double d = std::max(1.0, std::fabs(hi) * 0.1);
        lo -= d, hi += d;
    }
    const double pad = (hi - lo) * 0.06;
    if (!(include_zero && lo == 0)) lo -= pad;
    if (!(include_zero && hi == 0)) hi += pad;
    Range r;
    r.step = nice_step(hi - lo, target);
    r.lo = std::floor(lo / r.step + 1e-9) * r.step;
    r.hi = std::ceil(hi / r.step - 1e-9) * r.step;
    return r;
}

struct TimeUnit {
    double scale;
    const char* name;
};

TimeUnit time_unit_for(double step) {
    if (step >= 0.1) return {1, "s"};
    if (step >= 1e-4) return {1e-3, "ms"};
    return {1e-6, "\xc2\xb5s"};  // µs
}

struct Linear {
    double d0, d1, p0, p1;
    double operator()(double d) const { return p0 + (d - d0) * (p1 - p0) / (d1 - d0); }
};

// Polyline points in pixels, one decimal; repeats and the middle of
// horizontal or vertical runs dropped.
std::string polyline_points(const DataPoints& data, const Linear& x, const Linear& y) {
    std::vector<std::pair<std::string, std::string>> pts;
    pts.reserve(data.size());
    for (const auto& [dx, dy] : data) {
        const double px = std::clamp(x(dx), -1e5, 1e5), py = std::clamp(y(dy), -1e5, 1e5);
        std::pair<std::string, std::string> p{fixed(px, 1), fixed(py, 1)};
        if (!pts.empty() && pts.back() == p) continue;
        if (pts.size() >= 2) {
            const auto& a = pts[pts.size() - 2];
            const auto& b = pts.back();
            if ((a.second == b.second && b.second == p.second) || (a.first == b.first && b.first == p.first)) {
                // Same line: only drop the middle when it does not turn back.
                const double ax = std::stod(a.first), bx = std::stod(b.first), cx = std::stod(p.first);
                const double ay = std::stod(a.second), by = std::stod(b.second), cy = std::stod(p.second);
                if ((bx - ax) * (cx - bx) + (by - ay) * (cy - by) >= 0) {
                    pts.back() = std::move(p);
                    continue;
                }
            }
        }
        pts.push_back(std::move(p));
    }
    std::string out;
    out.reserve(pts.size() * 12);
    for (const auto& [a, b] : pts) {
        if (!out.empty()) out += ' ';
        out += a;
        out += ',';
        out += b;
    }
    return out;
}

// ---------------------------------------------------------------- SVG plots

struct LegendItem {
    std::string label;
    std::string color;
    double width = 2;
    std::string dash;  // stroke-dasharray, empty for solid
    std::string marker;  // "", "circle", "square": a marker instead of a line
};

// Appends a legend row at (x, y) (baseline of the text).
void append_legend(std::string& out, const std::vector<LegendItem>& items, double x, double y) {
    out += "<g class=\"legend\">";
    for (const LegendItem& item : items) {
        if (item.marker == "circle")
            out += "<circle cx=\"" + fixed(x + 9, 1) + "\" cy=\"" + fixed(y - 4, 1) + "\" r=\"4\" fill=\"" + item.color +
                   "\"/>";
        else if (item.marker == "square")
            out += "<rect x=\"" + fixed(x + 5, 1) + "\" y=\"" + fixed(y - 8, 1) + "\" width=\"8\" height=\"8\" fill=\"" +
                   item.color + "\"/>";
        else {
            out += "<line x1=\"" + fixed(x, 1) + "\" y1=\"" + fixed(y - 4, 1) + "\" x2=\"" + fixed(x + 18, 1) +
                   "\" y2=\"" + fixed(y - 4, 1) + "\" stroke=\"" + item.color + "\" stroke-width=\"" +
                   fixed(item.width, 1) + "\"";
            if (!item.dash.empty()) out += " stroke-dasharray=\"" + item.dash + "\"";
            out += "/>";
        }
        out += "<text x=\"" + fixed(x + 23, 1) + "\" y=\"" + fixed(y, 1) + "\">" + esc(item.label) + "</text>";
        x += 23 + 6.6 * static_cast<double>(item.label.size()) + 18;
    }
    out += "</g>";
}

// The plot area's border, drawn last so grid lines and series never cut it.
std::string frame_rect(int x, int y, int w, int h) {
    return "<rect class=\"frame\" x=\"" + std::to_string(x) + "\" y=\"" + std::to_string(y) + "\" width=\"" +
           std::to_string(w) + "\" height=\"" + std::to_string(h) + "\" fill=\"none\"/>";
}

struct PlotSeries {
    std::string name;
    std::string color;
    DataPoints points;
    double width = 1.6;
    double opacity = 1;
    std::string dash;
};

struct HLine {
    double y;
    std::string color;
    std::string label;
};

struct VMarker {
    double t;
    std::string label;
};

struct TimePlot {
    std::string id;
    std::string title;          // aria-label
    std::string extra_attrs;    // e.g. data-axis="x"
    double t0 = 0, t1 = 1;      // seconds
    std::string y_label;        // "velocity [mm/s]"
    Range y;
    bool binary = false;        // a wire: ticks "0" and "1" only
    int height = 150;           // plot area
    std::vector<PlotSeries> series;
    std::vector<HLine> hlines;
    std::vector<LegendItem> extra_legend;
    std::optional<VMarker> marker;
    std::vector<VMarker> events;                    // injected faults: dotted orange lines
    std::optional<std::pair<double, double>> shade;  // a time window to highlight
};

std::string render_time_plot(const TimePlot& plot) {
    const int L = kTimePlotMarginLeft, T = kTimePlotMarginTop, PW = kTimePlotWidth, PH = plot.height;
    const int W = L + PW + kTimePlotMarginRight, H = T + PH + kTimePlotMarginBottom;
    const Linear x{plot.t0, plot.t1, static_cast<double>(L), static_cast<double>(L + PW)};
    const Linear y{plot.y.lo, plot.y.hi, static_cast<double>(T + PH), static_cast<double>(T)};
    const std::string clip = "clip-" + plot.id;

    std::string out;
    out += "<svg class=\"plot\" id=\"" + plot.id + "\" xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
           std::to_string(W) + "\" height=\"" + std::to_string(H) + "\" viewBox=\"0 0 " + std::to_string(W) + " " +
           std::to_string(H) + "\" role=\"img\" aria-label=\"" + esc(plot.title) + "\" data-x-min=\"" +
           exact(plot.t0) + "\" data-x-max=\"" + exact(plot.t1) + "\" data-y-min=\"" + exact(plot.y.lo) +
           "\" data-y-max=\"" + exact(plot.y.hi) + "\" data-plot-left=\"" + std::to_string(L) +
           "\" data-plot-top=\"" + std::to_string(T) + "\" data-plot-width=\"" + std::to_string(PW) +
           "\" data-plot-height=\"" + std::to_string(PH) + "\"" + plot.extra_attrs + ">";
    out += "<defs><clipPath id=\"" + clip + "\"><rect x=\"" + std::to_string(L) + "\" y=\"" + std::to_string(T) +
           "\" width=\"" + std::to_string(PW) + "\" height=\"" + std::to_string(PH) + "\"/></clipPath></defs>";
    out += "<rect class=\"area\" x=\"" + std::to_string(L) + "\" y=\"" + std::to_string(T) + "\" width=\"" +
           std::to_string(PW) + "\" height=\"" + std::to_string(PH) + "\"/>";

    // Grid and ticks: time.
    const double t_step = nice_step(plot.t1 - plot.t0, 10);
    const TimeUnit unit = time_unit_for(t_step);
    const int t_decimals = decimals_for(t_step / unit.scale);
    std::string grid = "<g class=\"grid\">", ticks = "<g class=\"ticks\">";
    for (double t : tick_values(plot.t0, plot.t1, t_step)) {
        const std::string px = fixed(x(t), 1);
        grid += "<line x1=\"" + px + "\" y1=\"" + std::to_string(T) + "\" x2=\"" + px + "\" y2=\"" +
                std::to_string(T + PH) + "\"/>";
        ticks += "<text x=\"" + px + "\" y=\"" + std::to_string(T + PH + 15) + "\" text-anchor=\"middle\">" +
                 fixed(t / unit.scale, t_decimals) + "</text>";
    }
    // Grid and ticks: values.
    std::vector<double> y_ticks = plot.binary ? std::vector<double>{0, 1} : tick_values(plot.y.lo, plot.y.hi, plot.y.step);
    const int y_decimals = plot.binary ? 0 : decimals_for(plot.y.step);
    for (double v : y_ticks) {
        const std::string py = fixed(y(v), 1);
        grid += "<line x1=\"" + std::to_string(L) + "\" y1=\"" + py + "\" x2=\"" + std::to_string(L + PW) + "\" y2=\"" +
                py + "\"" + (v == 0 && !plot.binary ? " class=\"zero\"" : "") + "/>";
        ticks += "<text x=\"" + std::to_string(L - 6) + "\" y=\"" + fixed(y(v) + 4, 1) + "\" text-anchor=\"end\">" +
                 fixed(v, y_decimals) + "</text>";
    }
    out += grid + "</g>" + ticks + "</g>";
    out += "<text class=\"axis-label\" x=\"" + std::to_string(L + PW / 2) + "\" y=\"" + std::to_string(H - 6) +
           "\" text-anchor=\"middle\">time [" + std::string(unit.name) + "]</text>";
    out += "<text class=\"axis-label\" transform=\"translate(16," + std::to_string(T + PH / 2) +
           ") rotate(-90)\" text-anchor=\"middle\">" + esc(plot.y_label) + "</text>";

    if (plot.shade) {
        const double a = std::max(x(plot.shade->first), static_cast<double>(L));
        const double b = std::min(x(plot.shade->second), static_cast<double>(L + PW));
        out += "<rect class=\"zoom-window\" x=\"" + fixed(a, 1) + "\" y=\"" + std::to_string(T) + "\" width=\"" +
               fixed(std::max(1.0, b - a), 1) + "\" height=\"" + std::to_string(PH) + "\"/>";
    }

    out += "<g clip-path=\"url(#" + clip + ")\">";
    for (const HLine& h : plot.hlines) {
        const std::string py = fixed(y(h.y), 1);
        out += "<line class=\"target\" x1=\"" + std::to_string(L) + "\" y1=\"" + py + "\" x2=\"" +
               std::to_string(L + PW) + "\" y2=\"" + py + "\" stroke=\"" + h.color +
               "\" stroke-width=\"1.2\" stroke-dasharray=\"6 4\"/>";
        out += "<text class=\"target-label\" x=\"" + std::to_string(L + PW - 4) + "\" y=\"" + fixed(y(h.y) - 4, 1) +
               "\" text-anchor=\"end\" fill=\"" + h.color + "\">" + esc(h.label) + "</text>";
    }
    for (const PlotSeries& s : plot.series) {
        out += "<polyline class=\"series\" data-series=\"" + esc(s.name) + "\" fill=\"none\" stroke=\"" + s.color +
               "\" stroke-width=\"" + fixed(s.width, 1) + "\"";
        if (s.opacity < 1) out += " stroke-opacity=\"" + fixed(s.opacity, 2) + "\"";
        if (!s.dash.empty()) out += " stroke-dasharray=\"" + s.dash + "\"";
        out += " points=\"" + polyline_points(s.points, x, y) + "\"/>";
    }
    out += "</g>";

    if (plot.marker) {
        const double px = x(plot.marker->t);
        const bool right_half = px > L + PW * 0.6;
        out += "<line class=\"divergence\" x1=\"" + fixed(px, 1) + "\" y1=\"" + std::to_string(T - 2) + "\" x2=\"" +
               fixed(px, 1) + "\" y2=\"" + std::to_string(T + PH) + "\" stroke=\"" + kDivergenceColor +
               "\" stroke-width=\"2\" stroke-dasharray=\"5 3\"><title>" + esc(plot.marker->label) + "</title></line>";
        // Half-way up, where a wire (levels 0 and 1) leaves room, with a halo against lines.
        out += "<text class=\"divergence-label\" x=\"" + fixed(px + (right_half ? -5 : 5), 1) + "\" y=\"" +
               std::to_string(T + PH / 2 + 4) + "\" text-anchor=\"" + (right_half ? "end" : "start") + "\" fill=\"" +
               kDivergenceColor + "\">" + esc(plot.marker->label) + "</text>";
    }

    for (const VMarker& e : plot.events) {
        if (e.t < plot.t0 || e.t > plot.t1) continue;
        const double px = x(e.t);
        out += "<g class=\"fault-marker\" data-t=\"" + exact(e.t) + "\"><line x1=\"" + fixed(px, 1) + "\" y1=\"" +
               std::to_string(T) + "\" x2=\"" + fixed(px, 1) + "\" y2=\"" + std::to_string(T + PH) + "\" stroke=\"" +
               kFaultColor + "\" stroke-width=\"1.5\" stroke-dasharray=\"2 3\"><title>" + esc(e.label) +
               "</title></line><text x=\"" + fixed(px + 4, 1) + "\" y=\"" + std::to_string(T + 12) + "\" fill=\"" +
               kFaultColor + "\">" + esc(e.label) + "</text></g>";
    }

    std::vector<LegendItem> legend;
    for (const PlotSeries& s : plot.series) legend.push_back({s.name, s.color, std::max(2.0, s.width), s.dash, ""});
    for (const LegendItem& item : plot.extra_legend) legend.push_back(item);
    out += frame_rect(L, T, PW, PH);
    append_legend(out, legend, L, T - 10);
    out += "</svg>\n";
    return out;
}

// ---------------------------------------------------------------- report sections

struct Context {
    const RunReport& report;
    double end_s = 0;  // time axis of the run's plots: [0, end_s]
    std::vector<VMarker> fault_markers;  // drawn on every time plot
};

std::string plot_block(const std::string& heading, const std::string& svg) {
    return "<figure class=\"plot-block\"><figcaption>" + esc(heading) + "</figcaption>\n" + svg + "</figure>\n";
}

std::string finding_time(const Finding& f) {
    if (f.clock_hz == 0) return "cycle " + std::to_string(f.cycle);
    return seconds_text(to_seconds(f.cycle, f.clock_hz)) + "<br><span class=\"sub\">cycle " +
           std::to_string(f.cycle) + "</span>";
}

void append_findings(std::string& out, const RunReport& report) {
    out += "<section id=\"findings-section\"><h2>Findings</h2>\n";
    if (report.findings.empty()) {
        out += "<p class=\"none\" id=\"findings-none\">none</p></section>\n";
        return;
    }
    out += "<table id=\"findings\"><thead><tr><th>kind</th><th>source</th><th>time</th><th>PC / symbol</th>"
           "<th>detail</th></tr></thead><tbody>\n";
    const std::size_t rows = std::min(report.findings.size(), kMaxFindingRows);
    for (std::size_t i = 0; i < rows; ++i) {
        const Finding& f = report.findings[i];
        out += "<tr class=\"finding\"><td class=\"kind\">" + esc(to_string(f.kind)) + "</td><td>" + esc(f.source) +
               "</td><td class=\"num\">" + finding_time(f) + "</td><td class=\"mono\">";
        if (f.has_pc) {
            char pc[16];
            std::snprintf(pc, sizeof pc, "0x%04x", f.pc_bytes);
            out += pc;
            if (!f.symbol.empty()) out += " " + esc(f.symbol);
        } else
            out += "\xe2\x80\x94";  // —
        out += "</td><td>";
        append_escaped(out, f.detail, 1000);
        out += "</td></tr>\n";
    }
    out += "</tbody></table>\n";
    if (report.findings.size() > rows) {
        // The same summary line as the CLI prints: a count per kind and source.
        const auto summary = summarize_findings(report.findings, rows);
        out += "<p class=\"note\" id=\"findings-more\">";
        append_escaped(out, summary.back());
        out += " (" + std::to_string(report.findings.size()) + " in all)</p>\n";
    }
    out += "</section>\n";
}

// The zoom window around a divergence at `t`: wide enough to show about
// kZoomEvents distinct event times of either series on each side.
constexpr long kZoomEvents = 8;

std::vector<double> event_times(const Series& a, const Series& b) {
    std::vector<double> times;
    for (const Series* s : {&a, &b})
        for (const Sample& x : *s) times.push_back(x.t);
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    return times;
}

std::pair<double, double> centred_window(double t, double half) {
    half = std::max(half, 1e-6);
    const double lo = std::max(0.0, t - half);
    return {lo, std::max(t + half, lo + 2e-6)};
}

std::pair<double, double> zoom_window(const std::vector<double>& times, double t, double end) {
    double half = 0;
    const auto k = std::lower_bound(times.begin(), times.end(), t) - times.begin();
    const auto n = static_cast<long>(times.size());
    if (n > 0) {
        const long before = std::max(0L, k - kZoomEvents), after = std::min(n - 1, k + kZoomEvents);
        half = std::max(t - times[static_cast<std::size_t>(before)], times[static_cast<std::size_t>(after)] - t);
    }
    if (!(half > 0)) half = std::max(end * 0.05, 1e-6);
    return centred_window(t, half * 1.1);
}

// A tighter window, six times the distance from `t` to the nearest other
// event, so a small timing shift is as wide on screen as it is important;
// nullopt when there is no other event.
std::optional<std::pair<double, double>> detail_window(const std::vector<double>& times, double t) {
    double nearest = std::numeric_limits<double>::infinity();
    for (double x : times)
        if (x != t) nearest = std::min(nearest, std::fabs(x - t));
    if (!std::isfinite(nearest)) return std::nullopt;
    return centred_window(t, 6 * nearest);
}

Range value_range(const std::vector<const Series*>& all, double t0, double t1, bool include_zero) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Series* s : all) {
        for (std::size_t i = 0; i < s->size(); ++i) {
            const Sample& x = (*s)[i];
            const bool visible = x.t <= t1 && (i + 1 == s->size() || (*s)[i + 1].t >= t0);
            if (!visible) continue;
            lo = std::min(lo, x.v), hi = std::max(hi, x.v);
        }
    }
    if (lo > hi) lo = 0, hi = 1;
    return nice_range(lo, hi, include_zero);
}

void append_comparison(std::string& out, const Context& ctx) {
    const ComparisonView& cmp = *ctx.report.comparison;
    out += "<section id=\"comparison-section\"><h2>Comparison with the golden timeline</h2>\n";
    out += std::string("<p><span class=\"badge ") + (cmp.passed ? "good\">passed" : "bad\">FAILED") + "</span></p>\n";
    // The diff as the CLI prints it: one <pre>, its line breaks kept.
    out += "<pre id=\"comparison-summary\">";
    std::size_t at = 0;
    while (at <= cmp.summary.size()) {
        const std::size_t nl = std::min(cmp.summary.find('\n', at), cmp.summary.size());
        append_escaped(out, std::string_view(cmp.summary).substr(at, nl - at));
        if (nl < cmp.summary.size()) out += '\n';
        at = nl + 1;
    }
    out += "</pre>\n";
    const double div_t = to_seconds(cmp.first_divergence_cycle, cmp.first_divergence_clock_hz);
    if (!cmp.first_divergence_signal.empty())
        out += "<p>First divergence: <b class=\"mono\">" + esc(cmp.first_divergence_signal) + "</b> at " +
               seconds_text(div_t) + " (cycle " + std::to_string(cmp.first_divergence_cycle) + ")</p>\n";

    if (!cmp.channels.empty()) {
        out += "<table id=\"comparison-channels\"><thead><tr><th>signal</th><th>verdict</th><th>detail</th></tr></thead>"
               "<tbody>\n";
        for (const auto& row : cmp.channels) {
            const bool ok = row.verdict == "ok";
            out += std::string("<tr class=\"") + (ok ? "ok" : "diverged") + "\"><td class=\"mono\">" + esc(row.signal) +
                   "</td><td class=\"verdict\">" + esc(row.verdict) + "</td><td>";
            append_escaped(out, row.detail, 1000);
            out += "</td></tr>\n";
        }
        out += "</tbody></table>\n";
    }

    // Which channels to draw: the first divergence's, then the other non-ok ones.
    std::vector<std::string> names;
    if (!cmp.first_divergence_signal.empty()) names.push_back(cmp.first_divergence_signal);
    for (const auto& row : cmp.channels)
        if (row.verdict != "ok" && std::find(names.begin(), names.end(), row.signal) == names.end())
            names.push_back(row.signal);
    std::size_t drawn = 0;
    for (const std::string& name : names) {
        if (drawn == kMaxComparisonPlots) {
            out += "<p class=\"note\">" + std::to_string(names.size() - drawn) + " more diverging channels not drawn.</p>\n";
            break;
        }
        const long g = find_signal(cmp.golden, name);
        const long a = ctx.report.timeline != nullptr ? find_signal(*ctx.report.timeline, name) : -1;
        if (g < 0 && a < 0) {
            out += "<p class=\"note\">" + esc(name) + ": in neither timeline, nothing to draw.</p>\n";
            continue;
        }
        ++drawn;
        Series golden, actual;
        const SignalInfo* info = nullptr;
        if (g >= 0) {
            golden = extract(cmp.golden, {static_cast<SignalId>(g)})[0];
            info = &cmp.golden.signals()[static_cast<std::size_t>(g)];
        }
        if (a >= 0) {
            actual = extract(*ctx.report.timeline, {static_cast<SignalId>(a)})[0];
            info = &ctx.report.timeline->signals()[static_cast<std::size_t>(a)];
        }
        const bool binary = info->kind == SignalKind::Wire;
        const double end = std::max({ctx.end_s, last_time({golden, actual}), div_t, 1e-6});
        const bool is_first = name == cmp.first_divergence_signal;

        auto make_plot = [&](const std::string& id, double t0, double t1, bool zoomed) {
            TimePlot plot;
            plot.id = id;
            plot.title = name + (zoomed ? ": golden and actual around the first divergence" : ": golden and actual");
            plot.extra_attrs = " data-signal=\"" + esc(name) + "\"";
            plot.t0 = t0, plot.t1 = t1;
            plot.binary = binary;
            plot.height = binary ? 90 : 150;
            plot.y_label = binary ? "level" : info->kind == SignalKind::Bus ? "value" : name;
            if (binary) plot.y = {-0.25, 1.25, 1};
            else plot.y = value_range({&golden, &actual}, t0, t1, false);
            if (g >= 0)
                plot.series.push_back({"golden", kGoldenColor, step_points(golden, t0, t1, kTimePlotWidth), 6, 1, ""});
            if (a >= 0)
                plot.series.push_back({"actual", kActualColor, step_points(actual, t0, t1, kTimePlotWidth), 1.6, 1, ""});
            if (is_first) {
                plot.marker = VMarker{div_t, "first divergence " + seconds_text(div_t)};
                plot.extra_legend.push_back({"first divergence", kDivergenceColor, 2, "5 3", ""});
            }
            return plot;
        };

        const std::string id = "comparison-" + id_fragment(name);
        if (is_first) {
            const std::vector<double> times = event_times(golden, actual);
            const auto [z0, z1] = zoom_window(times, div_t, end);
            out += plot_block(name + " around the first divergence (" + seconds_text(z0) + " to " + seconds_text(z1) + ")",
                              render_time_plot(make_plot(id, z0, z1, true)));
            // A close-up when the context window would show the shift as a sliver.
            if (const auto detail = detail_window(times, div_t); detail && detail->second - detail->first < (z1 - z0) / 4)
                out += plot_block(name + " close-up (" + seconds_text(detail->first) + " to " +
                                      seconds_text(detail->second) + ")",
                                  render_time_plot(make_plot(id + "-detail", detail->first, detail->second, true)));
            TimePlot overview = make_plot(id + "-overview", 0, end, false);
            overview.shade = std::make_pair(z0, z1);
            overview.height = binary ? 60 : 110;
            out += plot_block(name + ", whole run (zoom window shaded)", render_time_plot(overview));
        } else {
            out += plot_block(name + ", whole run", render_time_plot(make_plot(id, 0, end, false)));
        }
    }
    out += "</section>\n";
}

struct Point3 {
    std::array<double, 3> c;
};

// The tool position after every change of any axis, in time order.
std::vector<Point3> merge_path(const std::vector<Series>& axes) {
    std::vector<Point3> path;
    std::array<double, 3> pos{0, 0, 0};
    std::array<std::size_t, 3> next{0, 0, 0};
    std::size_t total = 0;
    for (std::size_t a = 0; a < axes.size(); ++a) {
        if (!axes[a].empty()) pos[a] = axes[a][0].v, next[a] = 1;
        total += axes[a].size();
    }
    path.reserve(total + 1);
    path.push_back({pos});
    for (;;) {
        std::size_t best = axes.size();
        for (std::size_t a = 0; a < axes.size(); ++a)
            if (next[a] < axes[a].size() && (best == axes.size() || axes[a][next[a]].t < axes[best][next[best]].t))
                best = a;
        if (best == axes.size()) break;
        pos[best] = axes[best][next[best]].v;
        ++next[best];
        path.push_back({pos});
    }
    return path;
}

struct PixelPoint {
    double x, y;
};

double wrap_angle(double a) {
    constexpr double kPi = 3.14159265358979323846;
    while (a > kPi) a -= 2 * kPi;
    while (a < -kPi) a += 2 * kPi;
    return a;
}

// Streaming line simplification by cone intersection (Williams 1978): from
// an anchor, keep extending while one ray from it passes within `tolerance`
// of every point since; then the last point that fitted becomes the next
// anchor. Every output point is a point of the input, every input point is
// within `tolerance` of the output line, and straight runs (a stepper's
// staircase too) become one segment. O(n).
std::vector<PixelPoint> simplify_path(const std::vector<PixelPoint>& in, double tolerance) {
    std::vector<PixelPoint> out;
    if (in.empty()) return out;
    PixelPoint anchor = in.front(), last = anchor;
    out.push_back(anchor);
    bool have_cone = false;
    double centre = 0, width = 0;  // directions within [centre - width, centre + width] fit
    double farthest = 0;           // a path that turns back along its own ray must not be cut short
    for (std::size_t i = 1; i < in.size();) {
        const PixelPoint p = in[i];
        const double dx = p.x - anchor.x, dy = p.y - anchor.y;
        const double d = std::hypot(dx, dy);
        if (d <= tolerance) {  // no direction yet
            last = p;
            ++i;
            continue;
        }
        const double angle = std::atan2(dy, dx);
        const double half = std::asin(tolerance / d);
        if (!have_cone) {
            have_cone = true, centre = angle, width = half, last = p, farthest = d;
            ++i;
            continue;
        }
        const double delta = wrap_angle(angle - centre);
        if (delta >= -width && delta <= width && d >= farthest - tolerance) {
            farthest = std::max(farthest, d);
            const double lo = std::max(-width, delta - half), hi = std::min(width, delta + half);
            centre = wrap_angle(centre + (lo + hi) / 2), width = (hi - lo) / 2, last = p;
            ++i;
            continue;
        }
        // p leaves the cone: the last point that fitted is the next anchor; p is looked at again from it.
        out.push_back(last);
        anchor = last;
        have_cone = false;
    }
    if (out.size() == 1 || out.back().x != last.x || out.back().y != last.y) out.push_back(last);
    return out;
}

// A path too dense for a line (a scribble of millions of short moves) as the
// cells of the plot area it passes through, `cell` px square, one SVG subpath
// per horizontal run of cells; cells grow until at most kMaxCoverageRuns
// runs remain. Returns the path data and the cell size.
constexpr std::size_t kMaxCoverageRuns = 6000;

std::pair<std::string, double> coverage_path(const std::vector<PixelPoint>& in, int left, int top, int side) {
    for (double cell = 2;; cell *= 2) {
        const auto n = static_cast<long>(std::ceil(side / cell));
        std::vector<std::uint8_t> hit(static_cast<std::size_t>(n * n), 0);
        auto mark = [&](double x, double y) {
            const auto cx = static_cast<long>(std::floor((x - left) / cell)), cy = static_cast<long>(std::floor((y - top) / cell));
            if (cx >= 0 && cy >= 0 && cx < n && cy < n) hit[static_cast<std::size_t>(cy * n + cx)] = 1;
        };
        mark(in.front().x, in.front().y);
        for (std::size_t i = 1; i < in.size(); ++i) {  // sample each move at most half a cell apart
            const double dx = in[i].x - in[i - 1].x, dy = in[i].y - in[i - 1].y;
            const auto samples = static_cast<long>(std::min(1e6, std::ceil(std::hypot(dx, dy) / (cell / 2))));
            for (long k = 1; k <= samples; ++k) {
                const double f = static_cast<double>(k) / static_cast<double>(samples);
                mark(in[i - 1].x + dx * f, in[i - 1].y + dy * f);
            }
        }
        std::string d;
        std::size_t runs = 0;
        for (long cy = 0; cy < n; ++cy) {
            for (long cx = 0; cx < n;) {
                if (!hit[static_cast<std::size_t>(cy * n + cx)]) {
                    ++cx;
                    continue;
                }
                long end = cx;
                while (end < n && hit[static_cast<std::size_t>(cy * n + end)]) ++end;
                d += "M" + fixed(left + static_cast<double>(cx) * cell, 0) + "," + fixed(top + static_cast<double>(cy) * cell, 0) +
                     "h" + fixed(static_cast<double>(end - cx) * cell, 0) + "v" + fixed(cell, 0) + "h-" +
                     fixed(static_cast<double>(end - cx) * cell, 0) + "z";
                ++runs;
                cx = end;
            }
        }
        if (runs <= kMaxCoverageRuns || cell >= side) return {d, cell};
    }
}

std::string render_toolpath_view(const std::vector<Point3>& path, std::size_t ia, std::size_t ib,
                                 const std::string& name_a, const std::string& name_b, const std::string& id, int side) {
    const int L = kToolpathMarginLeft, T = kToolpathMarginTop;
    const int W = L + side + kToolpathMarginRight, H = T + side + kToolpathMarginBottom;
    double min_a = path[0].c[ia], max_a = min_a, min_b = path[0].c[ib], max_b = min_b;
    for (const Point3& p : path) {
        min_a = std::min(min_a, p.c[ia]), max_a = std::max(max_a, p.c[ia]);
        min_b = std::min(min_b, p.c[ib]), max_b = std::max(max_b, p.c[ib]);
    }
    double span = std::max(max_a - min_a, max_b - min_b);
    if (!(span > 0)) span = 1;
    const double scale = side / (1.1 * span);
    const double ca = (min_a + max_a) / 2, cb = (min_b + max_b) / 2;
    const double half = side / 2.0;
    auto px = [&](double a) { return L + half + (a - ca) * scale; };
    auto py = [&](double b) { return T + half - (b - cb) * scale; };

    std::vector<PixelPoint> pixels;
    pixels.reserve(path.size());
    for (const Point3& p : path) pixels.push_back({px(p.c[ia]), py(p.c[ib])});
    const std::vector<PixelPoint> line = simplify_path(pixels, kToolpathTolerancePx);
    const bool as_line = line.size() <= kMaxToolpathPoints;
    std::string drawing;
    double cell = 0;
    if (as_line) {
        drawing.reserve(line.size() * 12);
        for (const PixelPoint& q : line) {
            if (!drawing.empty()) drawing += ' ';
            drawing += fixed(q.x, 1) + "," + fixed(q.y, 1);
        }
    } else {
        std::tie(drawing, cell) = coverage_path(pixels, L, T, side);
    }

    const double a0 = ca - half / scale, a1 = ca + half / scale, b0 = cb - half / scale, b1 = cb + half / scale;
    std::string out;
    out += "<svg class=\"plot toolpath\" id=\"" + id + "\" xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
           std::to_string(W) + "\" height=\"" + std::to_string(H) + "\" viewBox=\"0 0 " + std::to_string(W) + " " +
           std::to_string(H) + "\" role=\"img\" aria-label=\"toolpath " + esc(name_a + name_b) + "\" data-x-min=\"" +
           exact(a0) + "\" data-x-max=\"" + exact(a1) + "\" data-y-min=\"" + exact(b0) + "\" data-y-max=\"" +
           exact(b1) + "\" data-plot-left=\"" + std::to_string(L) + "\" data-plot-top=\"" + std::to_string(T) +
           "\" data-plot-width=\"" + std::to_string(side) + "\" data-plot-height=\"" + std::to_string(side) +
           "\" data-scale=\"" + exact(scale) + "\" data-mode=\"" + (as_line ? "line" : "coverage") + "\"" +
           (as_line ? "" : " data-cell=\"" + exact(cell) + "\"") + ">";
    out += "<defs><clipPath id=\"clip-" + id + "\"><rect x=\"" + std::to_string(L) + "\" y=\"" + std::to_string(T) +
           "\" width=\"" + std::to_string(side) + "\" height=\"" + std::to_string(side) + "\"/></clipPath></defs>";
    out += "<rect class=\"area\" x=\"" + std::to_string(L) + "\" y=\"" + std::to_string(T) + "\" width=\"" +
           std::to_string(side) + "\" height=\"" + std::to_string(side) + "\"/>";
    const double step = nice_step(a1 - a0, 6);
    const int decimals = decimals_for(step);
    std::string grid_lines = "<g class=\"grid\">", ticks = "<g class=\"ticks\">";
    for (double v : tick_values(a0, a1, step)) {
        const std::string p = fixed(px(v), 1);
        grid_lines += "<line x1=\"" + p + "\" y1=\"" + std::to_string(T) + "\" x2=\"" + p + "\" y2=\"" +
                      std::to_string(T + side) + "\"" + (v == 0 ? " class=\"zero\"" : "") + "/>";
        ticks += "<text x=\"" + p + "\" y=\"" + std::to_string(T + side + 15) + "\" text-anchor=\"middle\">" +
                 fixed(v, decimals) + "</text>";
    }
    for (double v : tick_values(b0, b1, step)) {
        const std::string p = fixed(py(v), 1);
        grid_lines += "<line x1=\"" + std::to_string(L) + "\" y1=\"" + p + "\" x2=\"" + std::to_string(L + side) +
                      "\" y2=\"" + p + "\"" + (v == 0 ? " class=\"zero\"" : "") + "/>";
        ticks += "<text x=\"" + std::to_string(L - 6) + "\" y=\"" + fixed(py(v) + 4, 1) + "\" text-anchor=\"end\">" +
                 fixed(v, decimals) + "</text>";
    }
    out += grid_lines + "</g>" + ticks + "</g>";
    out += "<text class=\"axis-label\" x=\"" + std::to_string(L + side / 2) + "\" y=\"" + std::to_string(H - 6) +
           "\" text-anchor=\"middle\">" + esc(name_a) + " [mm]</text>";
    out += "<text class=\"axis-label\" transform=\"translate(16," + std::to_string(T + side / 2) +
           ") rotate(-90)\" text-anchor=\"middle\">" + esc(name_b) + " [mm]</text>";
    out += "<g clip-path=\"url(#clip-" + id + ")\">";
    if (as_line)
        out += "<polyline class=\"series\" data-series=\"path\" fill=\"none\" stroke=\"" + std::string(kToolpathColor) +
               "\" stroke-width=\"1.5\" stroke-linejoin=\"round\" points=\"" + drawing + "\"/>";
    else
        out += "<path class=\"coverage\" data-series=\"area covered\" fill=\"" + std::string(kToolpathColor) +
               "\" fill-opacity=\"0.6\" d=\"" + drawing + "\"/>";
    const PixelPoint first = pixels.front(), last = pixels.back();
    out += "<circle class=\"start\" cx=\"" + fixed(first.x, 1) + "\" cy=\"" + fixed(first.y, 1) +
           "\" r=\"5\" fill=\"#2ca02c\"/>";
    out += "<rect class=\"end\" x=\"" + fixed(last.x - 4, 1) + "\" y=\"" + fixed(last.y - 4, 1) +
           "\" width=\"8\" height=\"8\" fill=\"#d62728\"/></g>";
    out += frame_rect(L, T, side, side);
    append_legend(out, {{as_line ? "path" : "area covered (too dense for a line)", kToolpathColor, as_line ? 2.0 : 6.0, "", ""},
                        {"start", "#2ca02c", 0, "", "circle"}, {"end", "#d62728", 0, "", "square"}},
                  L, T - 10);
    out += "</svg>\n";
    return out;
}

void append_motion(std::string& out, const Context& ctx) {
    const RunReport& report = ctx.report;
    if (report.timeline == nullptr || report.axes.empty()) return;
    std::vector<SignalId> ids;
    for (const AxisSeries& a : report.axes) ids.push_back(a.position);
    const std::vector<Series> series = extract(*report.timeline, ids);

    std::vector<std::size_t> linear;
    for (std::size_t i = 0; i < report.axes.size(); ++i)
        if (!report.axes[i].rotary && linear.size() < 3) linear.push_back(i);
    if (linear.size() >= 2) {
        std::vector<Series> path_axes;
        for (std::size_t i : linear) path_axes.push_back(series[i]);
        const std::vector<Point3> path = merge_path(path_axes);
        auto name = [&](std::size_t k) { return report.axes[linear[k]].name; };
        out += "<section id=\"toolpath-section\"><h2>Toolpath</h2>\n<div class=\"views\">\n";
        if (linear.size() == 2) {
            out += plot_block(name(0) + name(1) + " (" + std::to_string(path.size()) + " positions)",
                              render_toolpath_view(path, 0, 1, name(0), name(1), "toolpath", kToolpathSide2D));
        } else {
            out += plot_block(name(0) + name(1) + " (top)",
                              render_toolpath_view(path, 0, 1, name(0), name(1), "toolpath", kToolpathSide3D));
            out += plot_block(name(0) + name(2) + " (front)",
                              render_toolpath_view(path, 0, 2, name(0), name(2), "toolpath-xz", kToolpathSide3D));
            out += plot_block(name(1) + name(2) + " (side)",
                              render_toolpath_view(path, 1, 2, name(1), name(2), "toolpath-yz", kToolpathSide3D));
        }
        out += "</div></section>\n";
    }

    out += "<section id=\"velocity-section\"><h2>Axis velocity</h2>\n";
    for (std::size_t i = 0; i < report.axes.size(); ++i) {
        const AxisSeries& axis = report.axes[i];
        const Series velocity = step_velocity(series[i]);
        TimePlot plot;
        plot.id = "velocity-" + id_fragment(axis.name);
        plot.title = "velocity of axis " + axis.name;
        plot.extra_attrs = " data-axis=\"" + esc(axis.name) + "\"";
        plot.t0 = 0, plot.t1 = ctx.end_s;
        const std::string unit = axis.rotary ? "deg/s" : "mm/s";
        plot.y_label = axis.name + " [" + unit + "]";
        double lo = 0, hi = 0;
        for (const Sample& x : velocity) lo = std::min(lo, x.v), hi = std::max(hi, x.v);
        plot.y = nice_range(lo, hi, true, 4);
        // A margin beyond zero, so an axis at rest is drawn inside the frame,
        // not hidden under its edge.
        const double margin = 0.05 * (plot.y.hi - plot.y.lo);
        if (plot.y.lo == 0) plot.y.lo = -margin;
        if (plot.y.hi == 0) plot.y.hi = margin;
        plot.height = 120;
        plot.events = ctx.fault_markers;
        plot.series.push_back({axis.name + " velocity [" + unit + "]", palette(i),
                               velocity.empty() ? DataPoints{} : step_points(velocity, 0, ctx.end_s, kTimePlotWidth), 1.6, 1, ""});
        out += plot_block("axis " + axis.name + ": " + std::to_string(series[i].size()) + " position changes",
                          render_time_plot(plot));
    }
    out += "</section>\n";
}

void append_thermal(std::string& out, const Context& ctx) {
    const RunReport& report = ctx.report;
    if (report.timeline == nullptr || report.temperatures.empty()) return;
    out += "<section id=\"thermal-section\"><h2>Temperatures and heater duty</h2>\n";
    TimePlot plot;
    plot.id = "temperatures";
    plot.title = "temperatures";
    plot.t0 = 0, plot.t1 = ctx.end_s;
    plot.y_label = "temperature [\xc2\xb0" "C]";
    plot.height = 200;
    plot.events = ctx.fault_markers;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    auto widen = [&](const Series& s) {
        for (const Sample& x : s) lo = std::min(lo, x.v), hi = std::max(hi, x.v);
    };
    for (std::size_t i = 0; i < report.temperatures.size(); ++i) {
        const TemperatureSeries& t = report.temperatures[i];
        const Series block = extract(*report.timeline, {t.temperature_degC}).front();
        widen(block);
        plot.series.push_back({t.name + " block", palette(i), step_points(block, 0, ctx.end_s, kTimePlotWidth), 1.8, 1, ""});
        if (t.sensor_degC) {
            const Series sensor = extract(*report.timeline, {*t.sensor_degC}).front();
            widen(sensor);
            plot.series.push_back({t.name + " sensor", palette(i), step_points(sensor, 0, ctx.end_s, kTimePlotWidth), 1.2,
                                   0.8, "4 2"});
        }
        if (!t.target_steps.empty()) {
            // The target holds from each command to the next, and to the end.
            Series target;
            for (const auto& [at, degC] : t.target_steps) target.push_back({at, degC});
            normalize(target);
            widen(target);
            DataPoints points;
            for (std::size_t k = 0; k < target.size(); ++k) {
                const double until = k + 1 < target.size() ? target[k + 1].t : ctx.end_s;
                points.emplace_back(target[k].t, target[k].v);
                points.emplace_back(until, target[k].v);
            }
            plot.series.push_back({t.name + " target", palette(i), points, 1.2, 1, "8 4"});
        }
        if (t.target_degC && std::isfinite(*t.target_degC)) {
            lo = std::min(lo, *t.target_degC), hi = std::max(hi, *t.target_degC);
            plot.hlines.push_back({*t.target_degC, palette(i), t.name + " target " + fixed(*t.target_degC, 1) + " \xc2\xb0" "C"});
            plot.extra_legend.push_back({t.name + " target", palette(i), 1.2, "6 4", ""});
        }
    }
    if (lo > hi) lo = 0, hi = 100;
    plot.y = nice_range(lo, hi, false);
    out += plot_block("temperature against time (block, sensor, target)", render_time_plot(plot));

    TimePlot dplot;
    dplot.id = "heater-duty";
    dplot.title = "heater duty";
    dplot.t0 = 0, dplot.t1 = ctx.end_s;
    dplot.y_label = "duty [%]";
    // 0..100 % with a margin, so a heater at 100 % is drawn inside the frame.
    dplot.y = {-5, 105, 25};
    dplot.height = 110;
    dplot.events = ctx.fault_markers;
    for (std::size_t i = 0; i < report.temperatures.size(); ++i) {
        const TemperatureSeries& t = report.temperatures[i];
        // The gate itself, averaged per pixel column: the duty where it
        // changes, not one sample window later.
        const std::optional<SignalId> source = t.heater_on ? t.heater_on : t.duty;
        if (!source) continue;
        Series duty = extract(*report.timeline, {*source}).front();
        if (duty.empty()) continue;
        for (Sample& x : duty) x.v *= 100;
        dplot.series.push_back({t.name + " heater", palette(i), mean_points(duty, 0, ctx.end_s, kTimePlotWidth), 1.4, 1, ""});
    }
    if (!dplot.series.empty()) out += plot_block("heater duty against time (gate on-time per pixel column)", render_time_plot(dplot));
    out += "</section>\n";
}

void append_servos(std::string& out, const Context& ctx) {
    const RunReport& report = ctx.report;
    if (report.timeline == nullptr || report.servos.empty()) return;
    std::vector<SignalId> ids;
    for (const ServoSeries& s : report.servos) ids.push_back(s.angle_deg);
    const std::vector<Series> angles = extract(*report.timeline, ids);
    out += "<section id=\"servo-section\"><h2>Servo angles</h2>\n";
    TimePlot plot;
    plot.id = "servos";
    plot.title = "servo angles";
    plot.t0 = 0, plot.t1 = ctx.end_s;
    plot.y_label = "angle [deg]";
    plot.height = 150;
    std::vector<const Series*> all;
    for (const Series& s : angles) all.push_back(&s);
    plot.y = value_range(all, 0, ctx.end_s, true);
    for (std::size_t i = 0; i < angles.size(); ++i)
        plot.series.push_back({report.servos[i].name, palette(i), step_points(angles[i], 0, ctx.end_s, kTimePlotWidth), 1.8, 1, ""});
    out += plot_block("servo angle against time", render_time_plot(plot));
    out += "</section>\n";
}

void append_transcript_line(std::string& out, const TranscriptLine& line) {
    out += line.from_host ? "<span class=\"from-host\">" : "<span class=\"from-firmware\">";
    char t[64];
    std::snprintf(t, sizeof t, "%10.6f s %11llu ", to_seconds(line.cycle, line.clock_hz), static_cast<unsigned long long>(line.cycle));
    out += "<span class=\"t\">";
    out += t;
    out += "</span>";
    out += line.from_host ? "<span class=\"dir\">host \xe2\x86\x92 fw</span>" : "<span class=\"dir\">fw \xe2\x86\x92 host</span>";
    out += ' ';
    append_escaped(out, line.text, kMaxTranscriptChars);
    out += "</span>\n";
}

void append_transcript(std::string& out, const RunReport& report) {
    out += "<section id=\"transcript-section\"><h2>UART transcript</h2>\n";
    const auto& lines = report.transcript;
    if (lines.empty()) {
        out += "<p class=\"none\" id=\"transcript-none\">none</p></section>\n";
        return;
    }
    std::size_t from_host = 0;
    for (const auto& l : lines) from_host += l.from_host ? 1 : 0;
    out += "<p class=\"legend-text\"><span class=\"from-host\">host \xe2\x86\x92 firmware</span>: " +
           std::to_string(from_host) + " lines, <span class=\"from-firmware\">firmware \xe2\x86\x92 host</span>: " +
           std::to_string(lines.size() - from_host) + " lines</p>\n";
    out += "<pre id=\"transcript\">";
    if (lines.size() <= kTranscriptHead + kTranscriptTail) {
        for (const auto& l : lines) append_transcript_line(out, l);
    } else {
        for (std::size_t i = 0; i < kTranscriptHead; ++i) append_transcript_line(out, lines[i]);
        out += "<span class=\"omitted\">\xe2\x80\xa6 " + std::to_string(lines.size() - kTranscriptHead - kTranscriptTail) +
               " lines omitted (" + std::to_string(lines.size()) + " in all) \xe2\x80\xa6</span>\n";
        for (std::size_t i = lines.size() - kTranscriptTail; i < lines.size(); ++i) append_transcript_line(out, lines[i]);
    }
    out += "</pre>\n</section>\n";
}

constexpr const char* kStyle = R"CSS(
:root { color-scheme: light; }
body { margin: 0; background: #eef0f3; color: #1d2330; font: 14px/1.45 "DejaVu Sans", "Liberation Sans", Arial, sans-serif; }
header.report { background: #1d2330; color: #f4f6f8; padding: 16px 20px 14px; }
header.report .wrap { max-width: 1060px; margin: 0 auto; }
header.report h1 { margin: 0 0 6px; font-size: 21px; font-weight: 600; }
header.report ul { margin: 6px 0 8px; padding: 0; list-style: none; columns: 2; column-gap: 32px; font-size: 13px; color: #c9d1dc; }
header.report li { break-inside: avoid; }
nav { font-size: 13px; margin-top: 6px; }
nav a { color: #9ecbff; margin-right: 14px; text-decoration: none; }
main { max-width: 1100px; margin: 0 auto; padding: 8px 20px 40px; }
section { background: #fff; border: 1px solid #d9dde3; border-radius: 6px; padding: 10px 18px 14px; margin: 14px 0; }
h2 { font-size: 17px; margin: 2px 0 8px; }
figure.plot-block { margin: 6px 0 10px; }
figcaption { font-size: 12.5px; color: #4a5261; margin-bottom: 2px; }
.views { display: flex; flex-wrap: wrap; gap: 4px 14px; }
svg.plot { display: block; max-width: 100%; height: auto; }
svg.plot text { font: 11px "DejaVu Sans", "Liberation Sans", Arial, sans-serif; fill: #3a4150; }
svg.plot text.axis-label { font-size: 12px; fill: #1d2330; }
svg.plot .area { fill: #fcfcfd; }
svg.plot .frame { stroke: #aab1bc; stroke-width: 1; shape-rendering: crispEdges; }
svg.plot .grid line { stroke: #e3e6eb; stroke-width: 1; shape-rendering: crispEdges; }
svg.plot .grid line.zero { stroke: #9aa2ad; }
svg.plot .zoom-window { fill: #ffd54f; fill-opacity: 0.35; }
svg.plot text.divergence-label { font-weight: bold; paint-order: stroke; stroke: #fcfcfd; stroke-width: 4px; stroke-linejoin: round; }
table { border-collapse: collapse; width: 100%; font-size: 13px; }
th { text-align: left; background: #f1f3f6; border-bottom: 2px solid #d3d8df; padding: 5px 8px; }
td { border-bottom: 1px solid #e6e9ed; padding: 4px 8px; vertical-align: top; }
tr.finding td { background: #fdecea; }
tr.finding td.kind { border-left: 4px solid #d62728; font-weight: bold; color: #a31515; white-space: nowrap; }
tr.diverged td { background: #fff4e0; }
tr.diverged td.verdict { font-weight: bold; color: #b35900; }
td.num { white-space: nowrap; font-variant-numeric: tabular-nums; }
.mono, pre { font-family: "DejaVu Sans Mono", "Liberation Mono", monospace; }
.sub { color: #6b7380; font-size: 11.5px; }
.badge { display: inline-block; padding: 1px 10px; border-radius: 10px; font-weight: bold; font-size: 13px; margin-right: 6px; }
.badge.bad { background: #d62728; color: #fff; }
.badge.good { background: #2ca02c; color: #fff; }
.badge.info { background: #3b4457; color: #fff; }
p.none { color: #2c7a3a; font-weight: bold; }
p.note { color: #5d6573; font-style: italic; }
pre#transcript { font-size: 12px; line-height: 1.4; background: #fafbfc; border: 1px solid #e1e4e8; padding: 8px 10px; max-height: 640px; overflow: auto; white-space: pre-wrap; margin: 4px 0 0; }
.from-host { color: #1f5fa8; }
.from-firmware { color: #18753a; }
.t { color: #8a919c; }
.dir { font-weight: bold; }
.omitted { color: #a15c00; font-style: italic; }
footer { color: #6b7380; font-size: 12px; text-align: center; margin: 12px 0 20px; }
)CSS";

}  // namespace

std::string format_html_report(const RunReport& report) {
    Context ctx{report, 0, {}};
    ctx.end_s = to_seconds(report.end_cycle, report.end_clock_hz);
    if (report.timeline != nullptr) {
        // The time axis reaches the last event of any plotted signal.
        std::vector<SignalId> ids;
        for (const auto& a : report.axes) ids.push_back(a.position);
        for (const auto& t : report.temperatures) {
            ids.push_back(t.temperature_degC);
            if (t.sensor_degC) ids.push_back(*t.sensor_degC);
            if (t.heater_on) ids.push_back(*t.heater_on);
            if (t.duty) ids.push_back(*t.duty);
        }
        for (const auto& s : report.servos) ids.push_back(s.angle_deg);
        const auto& signals = report.timeline->signals();
        for (SignalId id : ids)
            if (id >= signals.size())
                throw std::out_of_range("HTML report: signal id " + std::to_string(id) + " is not in the timeline (" +
                                        std::to_string(signals.size()) + " signals)");
        std::vector<bool> wanted(signals.size(), false);
        for (SignalId id : ids) wanted[id] = true;
        for (const TimelineEvent& e : report.timeline->events())
            if (e.signal < wanted.size() && wanted[e.signal])
                ctx.end_s = std::max(ctx.end_s, to_seconds(e.cycle, signals[e.signal].clock_hz));
    }
    if (!(ctx.end_s > 0)) ctx.end_s = 1e-3;
    for (const FaultMarker& f : report.faults) {
        char cycle[40];
        std::snprintf(cycle, sizeof cycle, " (%s, cycle %llu)", seconds_text(f.t_s).c_str(), static_cast<unsigned long long>(f.cycle));
        ctx.fault_markers.push_back({f.t_s, "fault " + f.label + cycle});
    }

    std::string out;
    out.reserve(1 << 16);
    out += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
    out += "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; style-src 'unsafe-inline'\">\n";
    out += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
    out += "<meta name=\"generator\" content=\"avrbench " AVRBENCH_VERSION "\">\n";
    out += "<title>" + esc(report.title.empty() ? std::string("avrbench run") : report.title) + "</title>\n";
    out += "<style>";
    out += kStyle;
    out += "</style>\n</head>\n<body>\n";

    // Header: title, facts, verdicts, contents.
    out += "<header class=\"report\" id=\"header\"><div class=\"wrap\">\n<h1>" + esc(report.title.empty() ? std::string("avrbench run") : report.title) +
           "</h1>\n<ul id=\"facts\">";
    for (const std::string& fact : report.facts) out += "<li>" + esc(fact) + "</li>";
    out += "<li>time axis: 0 to " + seconds_text(ctx.end_s) + "</li></ul>\n<p class=\"badges\">";
    out += report.findings.empty()
               ? std::string("<span class=\"badge good\">no findings</span>")
               : "<span class=\"badge bad\">" + std::to_string(report.findings.size()) +
                     (report.findings.size() == 1 ? " finding" : " findings") + "</span>";
    if (report.comparison)
        out += report.comparison->passed ? "<span class=\"badge good\">golden: passed</span>"
                                         : "<span class=\"badge bad\">golden: FAILED</span>";
    out += "</p>\n<nav><a href=\"#findings-section\">findings</a>";
    if (report.comparison) out += "<a href=\"#comparison-section\">comparison</a>";
    if (report.timeline != nullptr && !report.axes.empty()) out += "<a href=\"#velocity-section\">motion</a>";
    if (report.timeline != nullptr && !report.temperatures.empty()) out += "<a href=\"#thermal-section\">temperatures</a>";
    if (report.timeline != nullptr && !report.servos.empty()) out += "<a href=\"#servo-section\">servos</a>";
    out += "<a href=\"#transcript-section\">UART</a></nav>\n</div></header>\n<main>\n";

    append_findings(out, report);
    if (report.comparison) append_comparison(out, ctx);
    append_motion(out, ctx);
    append_thermal(out, ctx);
    append_servos(out, ctx);
    append_transcript(out, report);
    out += "</main>\n<footer>avrbench " AVRBENCH_VERSION " \xc2\xb7 self-contained report, no network</footer>\n</body>\n</html>\n";
    return out;
}

void write_html_report(const RunReport& report, const std::string& path) {
    const std::string html = format_html_report(report);
    write_output_file(path, html, "HTML report");
}

}  // namespace avrbench
