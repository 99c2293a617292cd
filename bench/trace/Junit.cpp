#include "trace/Junit.hpp"

#include <cstdio>

namespace avrbench {
namespace {

// Length of the UTF-8 sequence starting at s[i], or 0 if it is not one.
std::size_t utf8_length(const std::string& s, std::size_t i) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (n == 0 || i + n > s.size()) return 0;
    for (std::size_t k = 1; k < n; ++k) {
        if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
    }
    return n;
}

}  // namespace

std::string xml_escape(const std::string& text, bool attribute) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size();) {
        const char c = text[i];
        const std::size_t n = utf8_length(text, i);
        if (n == 0) {
            out += '?';
            ++i;
            continue;
        }
        if (n > 1) {
            out.append(text, i, n);
            i += n;
            continue;
        }
        switch (c) {
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '&': out += "&amp;"; break;
            case '"': out += "&quot;"; break;
            case '\n': out += attribute ? "&#10;" : "\n"; break;
            case '\t': out += attribute ? "&#9;" : "\t"; break;
            default: out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
        }
        ++i;
    }
    return out;
}

std::string junit_xml(const std::vector<JunitCase>& cases, const std::string& suite_name) {
    std::size_t failures = 0, errors = 0;
    double total = 0;
    for (const auto& c : cases) {
        failures += c.outcome == JunitCase::Outcome::Failed ? 1 : 0;
        errors += c.outcome == JunitCase::Outcome::Error ? 1 : 0;
        total += c.time_s;
    }
    auto seconds = [](double s) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.3f", s);
        return std::string(buf);
    };
    std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    out += "<testsuites>\n";
    out += "<testsuite name=\"" + xml_escape(suite_name, true) + "\" tests=\"" + std::to_string(cases.size()) +
           "\" failures=\"" + std::to_string(failures) + "\" errors=\"" + std::to_string(errors) + "\" time=\"" +
           seconds(total) + "\">\n";
    for (const auto& c : cases) {
        out += "  <testcase classname=\"" + xml_escape(c.classname, true) + "\" name=\"" + xml_escape(c.name, true) +
               "\" time=\"" + seconds(c.time_s) + "\"";
        if (c.outcome == JunitCase::Outcome::Passed) {
            out += "/>\n";
            continue;
        }
        const char* tag = c.outcome == JunitCase::Outcome::Failed ? "failure" : "error";
        out += ">\n    <" + std::string(tag) + " message=\"" + xml_escape(c.message, true) + "\">" +
               xml_escape(c.text, false) + "</" + tag + ">\n  </testcase>\n";
    }
    out += "</testsuite>\n</testsuites>\n";
    return out;
}

}  // namespace avrbench
