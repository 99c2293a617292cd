#include "trace/html/ReportParts.hpp"

#include <cstdio>

namespace avrbench::html_report {

namespace {

void append_cells(std::string& out, const std::array<Cycle, 4>& stats) {
    for (const Cycle c : stats) out += "<td>" + std::to_string(c) + "</td>";
}

}  // namespace

void append_timing(std::string& out, const RunReport& report) {
    if (report.timing.empty()) return;
    out += "<section id=\"timing-section\"><h2>Timing profile</h2>\n";
    out += "<p class=\"legend-text\">cycles from the vector's first instruction to the end of RETI (inclusive of nested "
           "ISRs, and exclusive of them); latency from the flag raised with the interrupt enabled to the vector's "
           "first instruction; min / median / p99 / max</p>\n";
    for (const TimingTable& t : report.timing) {
        out += "<h3>";
        append_escaped(out, t.mcu);
        out += "</h3>\n<ul class=\"timing-facts\">";
        for (const auto& fact : t.facts) {
            out += "<li>";
            append_escaped(out, fact);
            out += "</li>";
        }
        out += "</ul>\n<table class=\"timing\" id=\"timing-" + id_fragment(t.mcu) + "\">\n";
        out += "<tr><th rowspan=\"2\">vector</th><th rowspan=\"2\">runs</th><th colspan=\"4\">inclusive</th>"
               "<th colspan=\"4\">exclusive</th><th colspan=\"4\">latency</th><th rowspan=\"2\">depth</th></tr>\n<tr>";
        for (int k = 0; k < 3; ++k) out += "<th>min</th><th>median</th><th>p99</th><th>max</th>";
        out += "</tr>\n";
        for (const auto& row : t.rows) {
            out += "<tr><td>" + std::to_string(row.vector) + "</td><td>" + std::to_string(row.runs) + "</td>";
            append_cells(out, row.inclusive);
            append_cells(out, row.exclusive);
            append_cells(out, row.latency);
            out += "<td>" + std::to_string(row.max_depth) + "</td></tr>\n";
        }
        out += "</table>\n";
    }
    out += "</section>\n";
}

}  // namespace avrbench::html_report
