#include "trace/html/ReportParts.hpp"

namespace avrbench::html_report {

namespace {
// A long run redraws its screen thousands of times; the report keeps the
// last ones (the summary and Python have the final screen, screens() all).
constexpr std::size_t kMaxScreens = 200;
}  // namespace

void append_displays(std::string& out, const RunReport& report) {
    if (report.displays.empty()) return;
    out += "<section id=\"display-section\"><h2>Displays</h2>\n";
    for (const DisplayScreens& d : report.displays) {
        out += "<h3>";
        append_escaped(out, d.part);
        const std::size_t first = d.screens.size() > kMaxScreens ? d.screens.size() - kMaxScreens : 0;
        out += "</h3>\n";
        if (first > 0) out += "<p class=\"legend-text\">the last " + std::to_string(kMaxScreens) + " of " + std::to_string(d.screens.size()) + " screens</p>\n";
        out += "<div class=\"screens\" id=\"display-" + id_fragment(d.part) + "\">\n";
        for (std::size_t i = first; i < d.screens.size(); ++i) {
            const auto& [cycle, lines] = d.screens[i];
            out += "<figure class=\"screen\"><figcaption>" + seconds_text(static_cast<double>(cycle) / d.clock_hz) +
                   "</figcaption><pre>";
            for (std::size_t l = 0; l < lines.size(); ++l) {
                if (l > 0) out += "\n";
                append_escaped(out, lines[l]);
            }
            out += "</pre></figure>\n";
        }
        out += "</div>\n";
    }
    out += "</section>\n";
}

}  // namespace avrbench::html_report
