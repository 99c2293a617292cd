#include "trace/html/ReportParts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

namespace avrbench::html_report {

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

}  // namespace avrbench::html_report
