#include "trace/html/ReportParts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

namespace avrbench::html_report {

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

// Every byte of a character bus (a UART), repeats included, with its time.
std::vector<std::pair<double, std::uint8_t>> byte_events(const Timeline& timeline, SignalId id) {
    std::vector<std::pair<double, std::uint8_t>> out;
    const SignalInfo& info = timeline.signals()[id];
    for (const TimelineEvent& e : timeline.events())
        if (e.signal == id) out.emplace_back(to_seconds(e.cycle, info.clock_hz), static_cast<std::uint8_t>(e.value.bits));
    return out;
}

// The bytes of a UART around the first one that differs, as text (C-style
// escapes for control bytes), golden above actual, the differing byte marked:
// a byte stream read as a number would be a meaningless line from 0 to 140.
std::string byte_comparison(const std::string& id, const std::vector<std::pair<double, std::uint8_t>>& golden,
                            const std::vector<std::pair<double, std::uint8_t>>& actual) {
    std::size_t k = 0;
    while (k < golden.size() && k < actual.size() && golden[k] == actual[k]) ++k;
    constexpr std::size_t kContext = 40;
    const std::size_t from = k > kContext ? k - kContext : 0;
    auto row = [&](const char* label, const std::vector<std::pair<double, std::uint8_t>>& bytes) {
        std::string cells = std::string("<tr><td>") + label + "</td><td class=\"num\">";
        cells += k < bytes.size() ? seconds_text(bytes[k].first) : std::string("(ended)");
        cells += "</td><td class=\"mono bytes\">";
        if (from > 0) cells += "\u2026";
        for (std::size_t i = from; i < bytes.size() && i < k + kContext; ++i) {
            const std::uint8_t b = bytes[i].second;
            char text[8];
            if (b == '\n') std::snprintf(text, sizeof text, "\\n");
            else if (b == '\r') std::snprintf(text, sizeof text, "\\r");
            else if (b < 0x20 || b >= 0x7f) std::snprintf(text, sizeof text, "\\x%02x", b);
            else std::snprintf(text, sizeof text, "%c", static_cast<char>(b));
            if (i == k) cells += "<mark>";
            cells += esc(text);
            if (i == k) cells += "</mark>";
        }
        if (from + 2 * kContext < bytes.size() && k + kContext < bytes.size()) cells += "\u2026";
        return cells + "</td></tr>\n";
    };
    std::string out = "<table class=\"byte-comparison\" id=\"" + id + "\"><thead><tr><th></th><th>byte " +
                      std::to_string(k + 1) + " at</th><th>bytes around it (the first that differs marked)</th></tr></thead><tbody>\n";
    out += row("golden", golden);
    out += row("actual", actual);
    return out + "</tbody></table>\n";
}

// The verdict, the diff as the CLI prints it and the table of channels.
void append_comparison_text(std::string& out, const ComparisonView& cmp, double div_t) {
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
    if (!cmp.first_divergence_signal.empty())
        out += "<p>First divergence: <b class=\"mono\">" + esc(cmp.first_divergence_signal) + "</b> at " +
               seconds_text(div_t) + " (cycle " + std::to_string(cmp.first_divergence_cycle) + ")</p>\n";

    if (!cmp.channels.empty()) {
        out += "<table id=\"comparison-channels\"><thead><tr><th>signal</th><th>verdict</th><th>detail</th></tr></thead>"
               "<tbody>\n";
        for (const auto& row : cmp.channels) {
            // "new": recorded now, not in the golden, not checked.
            const bool ok = row.verdict == "ok" || row.verdict == "new";
            out += std::string("<tr class=\"") + (ok ? "ok" : "diverged") + "\"><td class=\"mono\">" + esc(row.signal) +
                   "</td><td class=\"verdict\">" + esc(row.verdict) + "</td><td>";
            append_escaped(out, row.detail, 1000);
            out += "</td></tr>\n";
        }
        out += "</tbody></table>\n";
    }

}

// Golden and actual of one channel: zoomed on the first divergence (with a
// close-up and the whole run) for its channel, the whole run for the others.
// False when neither timeline has it (nothing drawn).
bool append_channel_plot(std::string& out, const Context& ctx, const std::string& name, double div_t) {
    const ComparisonView& cmp = *ctx.report.comparison;
    const long g = find_signal(cmp.golden, name);
    const long a = ctx.report.timeline != nullptr ? find_signal(*ctx.report.timeline, name) : -1;
    if (g < 0 && a < 0) {
        out += "<p class=\"note\">" + esc(name) + ": in neither timeline, nothing to draw.</p>\n";
        return false;
    }
    const SignalInfo& any_info = g >= 0 ? cmp.golden.signals()[static_cast<std::size_t>(g)]
                                        : ctx.report.timeline->signals()[static_cast<std::size_t>(a)];
    if (any_info.kind == SignalKind::Bus && any_info.characters) {
        out += plot_block(name + ": bytes, golden and actual", byte_comparison("comparison-" + id_fragment(name),
                               g >= 0 ? byte_events(cmp.golden, static_cast<SignalId>(g)) : decltype(byte_events(cmp.golden, 0)){},
                               a >= 0 ? byte_events(*ctx.report.timeline, static_cast<SignalId>(a))
                                      : decltype(byte_events(cmp.golden, 0)){}));
        return true;
    }
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
    return true;
}

void append_comparison(std::string& out, const Context& ctx) {
    const ComparisonView& cmp = *ctx.report.comparison;
    const double div_t = to_seconds(cmp.first_divergence_cycle, cmp.first_divergence_clock_hz);
    append_comparison_text(out, cmp, div_t);
    // Which channels to draw: the first divergence's, then the other non-ok ones.
    std::vector<std::string> names;
    if (!cmp.first_divergence_signal.empty()) names.push_back(cmp.first_divergence_signal);
    for (const auto& row : cmp.channels)
        if (row.verdict != "ok" && row.verdict != "new" && std::find(names.begin(), names.end(), row.signal) == names.end())
            names.push_back(row.signal);
    std::size_t drawn = 0;
    for (const std::string& name : names) {
        if (drawn == kMaxComparisonPlots) {
            out += "<p class=\"note\">" + std::to_string(names.size() - drawn) + " more diverging channels not drawn.</p>\n";
            break;
        }
        if (append_channel_plot(out, ctx, name, div_t)) ++drawn;
    }
    out += "</section>\n";
}

}  // namespace avrbench::html_report
