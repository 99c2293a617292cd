#include "trace/html/ReportParts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

namespace avrbench::html_report {

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

Range nice_range(double lo, double hi, bool include_zero, double target) {
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

TimeUnit time_unit_for(double step) {
    if (step >= 0.1) return {1, "s"};
    if (step >= 1e-4) return {1e-3, "ms"};
    return {1e-6, "\xc2\xb5s"};  // µs
}

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

std::string frame_rect(int x, int y, int w, int h) {
    return "<rect class=\"frame\" x=\"" + std::to_string(x) + "\" y=\"" + std::to_string(y) + "\" width=\"" +
           std::to_string(w) + "\" height=\"" + std::to_string(h) + "\" fill=\"none\"/>";
}

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

}  // namespace avrbench::html_report
