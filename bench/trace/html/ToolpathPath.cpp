#include "trace/html/ReportParts.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

namespace avrbench::html_report {

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

double wrap_angle(double a) {
    while (a > std::numbers::pi) a -= 2 * std::numbers::pi;
    while (a < -std::numbers::pi) a += 2 * std::numbers::pi;
    return a;
}

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

}  // namespace avrbench::html_report
