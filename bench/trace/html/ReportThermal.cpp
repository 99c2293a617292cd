#include "trace/html/ReportParts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

namespace avrbench::html_report {

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

}  // namespace avrbench::html_report
