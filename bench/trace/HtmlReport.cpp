#include "trace/HtmlReport.hpp"

#include "core/OutputFile.hpp"
#include "trace/html/ReportParts.hpp"

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
.screens { display: flex; flex-wrap: wrap; gap: 10px; }
figure.screen { margin: 0; }
figure.screen pre { background: #2b4a1e; color: #d8f5c0; padding: 6px 8px; margin: 2px 0 0; font-size: 12px; line-height: 1.25; }
figure.screen figcaption { font-size: 11px; color: #5b6472; }
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
pre#comparison-summary { font-size: 12px; background: #fafbfc; border: 1px solid #e1e4e8; padding: 8px 10px; white-space: pre-wrap; overflow-wrap: anywhere; max-height: 640px; overflow: auto; }
table.byte-comparison td.bytes { overflow-wrap: anywhere; }
table.byte-comparison mark { background: #ffd54f; font-weight: bold; }
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
    if (!report.timing.empty()) out += "<a href=\"#timing-section\">timing</a>";
    if (!report.displays.empty()) out += "<a href=\"#display-section\">displays</a>";
    out += "<a href=\"#transcript-section\">UART</a></nav>\n</div></header>\n<main>\n";

    append_findings(out, report);
    if (report.comparison) append_comparison(out, ctx);
    append_motion(out, ctx);
    append_thermal(out, ctx);
    append_servos(out, ctx);
    append_timing(out, report);
    append_displays(out, report);
    append_transcript(out, report);
    out += "</main>\n<footer>avrbench " AVRBENCH_VERSION " \xc2\xb7 self-contained report, no network</footer>\n</body>\n</html>\n";
    return out;
}

void write_html_report(const RunReport& report, const std::string& path) {
    const std::string html = format_html_report(report);
    write_output_file(path, html, "HTML report");
}

}  // namespace avrbench
