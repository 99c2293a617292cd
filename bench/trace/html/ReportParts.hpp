// The pieces of the HTML run report (trace/HtmlReport.cpp assembles them):
// text escaping (HtmlText), signal series and their sampling (HtmlSeries),
// SVG time plots with scales and ticks (SvgPlot), the tool path and its
// simplifier (ToolpathPath), and one file per report section
// (ReportComparison, ReportMotion, ReportThermal, ReportTranscript).
// Internal to the trace layer: not for use outside bench/trace.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "trace/RunReport.hpp"
#include "trace/html/ReportLayout.hpp"
#include "trace/Timeline.hpp"

namespace avrbench::html_report {

inline constexpr std::size_t kNoLimit = std::numeric_limits<std::size_t>::max();

// Series colours (colour-blind friendly enough, distinct on white).
inline constexpr std::array<const char*, 8> kPalette = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                                 "#9467bd", "#8c564b", "#e377c2", "#17becf"};

inline constexpr const char* kFaultColor = "#e66100";

inline constexpr const char* kToolpathColor = "#1f77b4";

inline constexpr const char* kGoldenColor = "#8fbce6";

inline constexpr const char* kActualColor = "#1d2330";

inline constexpr const char* kDivergenceColor = "#d62728";

struct Sample {
    double t;  // seconds
    double v;
};

using Series = std::vector<Sample>;

using DataPoints = std::vector<std::pair<double, double>>;

struct Range {
    double lo = 0, hi = 1, step = 0.2;
};

struct TimeUnit {
    double scale;
    const char* name;
};

struct Linear {
    double d0, d1, p0, p1;
    double operator()(double d) const { return p0 + (d - d0) * (p1 - p0) / (d1 - d0); }
};

struct LegendItem {
    std::string label;
    std::string color;
    double width = 2;
    std::string dash;  // stroke-dasharray, empty for solid
    std::string marker;  // "", "circle", "square": a marker instead of a line
};

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

struct Context {
    const RunReport& report;
    double end_s = 0;  // time axis of the run's plots: [0, end_s]
    std::vector<VMarker> fault_markers;  // drawn on every time plot
};

// The zoom window around a divergence at `t`: wide enough to show about
// kZoomEvents distinct event times of either series on each side.
inline constexpr long kZoomEvents = 8;

struct Point3 {
    std::array<double, 3> c;
};

struct PixelPoint {
    double x, y;
};

// A path too dense for a line (a scribble of millions of short moves) as the
// cells of the plot area it passes through, `cell` px square, one SVG subpath
// per horizontal run of cells; cells grow until at most kMaxCoverageRuns
// runs remain. Returns the path data and the cell size.
inline constexpr std::size_t kMaxCoverageRuns = 6000;

const char* palette(std::size_t i);

void append_hex_escape(std::string& out, unsigned char c);

// Length of the valid UTF-8 sequence at text[i], or 0 when it is not one.
std::size_t utf8_sequence(std::string_view text, std::size_t i);

// HTML-escapes `text` onto `out`; control characters and bytes that are not
// valid UTF-8 become \xNN. At most `max_chars` characters are written, then
// an ellipsis. Returns true when it cut the text.
bool append_escaped(std::string& out, std::string_view text, std::size_t max_chars = kNoLimit);

std::string esc(std::string_view text);

// Fixed-point with `decimals` digits, never "-0".
std::string fixed(double value, int decimals);

// Shortest text that reads back to the same double (for data-* attributes).
std::string exact(double value);

std::string seconds_text(double seconds);

double to_seconds(Cycle cycle, std::uint32_t clock_hz);

double event_value(const SignalInfo& info, const TimelineEvent& e);

// Time order; at one time the last recorded value wins; repeats and values
// that are not finite are dropped.
void normalize(Series& s);

// The series of each id, in one pass over the events.
std::vector<Series> extract(const Timeline& timeline, const std::vector<SignalId>& ids);

double last_time(const std::vector<Series>& all);

// -1 when the timeline has no signal named "scope.name".
long find_signal(const Timeline& timeline, const std::string& full_name);

// A step function (the value holds until the next sample) over [t0, t1] as
// polyline points in data coordinates: exact when there is at most one change
// per column, else per column entering value, min and max in order, leaving value.
DataPoints step_points(const Series& s, double t0, double t1, int columns);

// A step function as its time average per column when it changes more than
// once per column (a PWM duty), else exactly as step_points draws it.
DataPoints mean_points(const Series& s, double t0, double t1, int columns);

// An axis's velocity per plot column: the mean of the position changes
// inside a window centred on the column (4 columns or `min_window_s`,
// whichever is longer), from the first change to the last, so a steady step
// rate reads as exactly its velocity and quantised positions do not spike.
Series windowed_velocity(const Series& position, double t0, double t1, int columns, double min_window_s);

double nice_step(double range, double target);

int decimals_for(double step);

std::vector<double> tick_values(double lo, double hi, double step);

// A padded range with round ends, for a value axis.
Range nice_range(double lo, double hi, bool include_zero, double target = 5);

TimeUnit time_unit_for(double step);

// Polyline points in pixels, one decimal; repeats and the middle of
// horizontal or vertical runs dropped.
std::string polyline_points(const DataPoints& data, const Linear& x, const Linear& y);

// Appends a legend row at (x, y) (baseline of the text).
void append_legend(std::string& out, const std::vector<LegendItem>& items, double x, double y);

// The plot area's border, drawn last so grid lines and series never cut it.
std::string frame_rect(int x, int y, int w, int h);

std::string render_time_plot(const TimePlot& plot);

std::string plot_block(const std::string& heading, const std::string& svg);

std::string finding_time(const Finding& f);

void append_findings(std::string& out, const RunReport& report);

std::vector<double> event_times(const Series& a, const Series& b);

std::pair<double, double> centred_window(double t, double half);

std::pair<double, double> zoom_window(const std::vector<double>& times, double t, double end);

// A tighter window, six times the distance from `t` to the nearest other
// event, so a small timing shift is as wide on screen as it is important;
// nullopt when there is no other event.
std::optional<std::pair<double, double>> detail_window(const std::vector<double>& times, double t);

Range value_range(const std::vector<const Series*>& all, double t0, double t1, bool include_zero);

void append_comparison(std::string& out, const Context& ctx);

// The tool position after every change of any axis, in time order.
std::vector<Point3> merge_path(const std::vector<Series>& axes);

double wrap_angle(double a);

// Streaming line simplification by cone intersection (Williams 1978): from
// an anchor, keep extending while one ray from it passes within `tolerance`
// of every point since; then the last point that fitted becomes the next
// anchor. Every output point is a point of the input, every input point is
// within `tolerance` of the output line, and straight runs (a stepper's
// staircase too) become one segment. O(n).
std::vector<PixelPoint> simplify_path(const std::vector<PixelPoint>& in, double tolerance);

std::pair<std::string, double> coverage_path(const std::vector<PixelPoint>& in, int left, int top, int side);

std::string render_toolpath_view(const std::vector<Point3>& path, std::size_t ia, std::size_t ib, const std::string& name_a, const std::string& name_b, const std::string& id, int side);

void append_motion(std::string& out, const Context& ctx);

void append_thermal(std::string& out, const Context& ctx);

void append_servos(std::string& out, const Context& ctx);

void append_transcript_line(std::string& out, const TranscriptLine& line);

void append_transcript(std::string& out, const RunReport& report);

// <section id="timing-section">: per profiled MCU its facts and a
// <table class="timing" id="timing-<mcu>"> of vectors; left out when no MCU was profiled.
void append_timing(std::string& out, const RunReport& report);
// Each display's screens with their times (at most kMaxScreens per display, the last ones).
void append_displays(std::string& out, const RunReport& report);

}  // namespace avrbench::html_report
