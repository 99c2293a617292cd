#include "trace/html/ReportParts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

namespace avrbench::html_report {

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
        // Averaged over at least 10 ms: a derivative of quantised position
        // would swing by a whole step per interval.
        constexpr double kMinVelocityWindowS = 0.010;
        const Series velocity = windowed_velocity(series[i], 0, ctx.end_s, kTimePlotWidth, kMinVelocityWindowS);
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
        out += plot_block("axis " + axis.name + ": " + std::to_string(series[i].size()) +
                              " position changes; velocity from first to last change in each window of " +
                              std::to_string(static_cast<int>(std::lround(1000 * std::max(kMinVelocityWindowS, 4 * ctx.end_s / kTimePlotWidth)))) + " ms",
                          render_time_plot(plot));
    }
    out += "</section>\n";
}

}  // namespace avrbench::html_report
