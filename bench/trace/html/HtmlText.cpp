#include "trace/html/ReportParts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

namespace avrbench::html_report {

const char* palette(std::size_t i) { return kPalette[i % kPalette.size()]; }

void append_hex_escape(std::string& out, unsigned char c) {
    static const char* digits = "0123456789abcdef";
    out += "\\x";
    out += digits[c >> 4];
    out += digits[c & 15];
}

std::size_t utf8_sequence(std::string_view text, std::size_t i) {
    const auto b0 = static_cast<unsigned char>(text[i]);
    std::size_t len = 0;
    unsigned char lo = 0x80, hi = 0xbf;  // allowed range of the second byte
    if (b0 >= 0xc2 && b0 <= 0xdf) len = 2;
    else if (b0 >= 0xe0 && b0 <= 0xef) {
        len = 3;
        if (b0 == 0xe0) lo = 0xa0;
        if (b0 == 0xed) hi = 0x9f;  // no surrogates
    } else if (b0 >= 0xf0 && b0 <= 0xf4) {
        len = 4;
        if (b0 == 0xf0) lo = 0x90;
        if (b0 == 0xf4) hi = 0x8f;
    } else
        return 0;
    if (i + len > text.size()) return 0;
    for (std::size_t k = 1; k < len; ++k) {
        const auto b = static_cast<unsigned char>(text[i + k]);
        const unsigned char klo = k == 1 ? lo : 0x80, khi = k == 1 ? hi : 0xbf;
        if (b < klo || b > khi) return 0;
    }
    return len;
}

bool append_escaped(std::string& out, std::string_view text, std::size_t max_chars) {
    std::size_t chars = 0;
    for (std::size_t i = 0; i < text.size();) {
        if (chars == max_chars) {
            out += "\xe2\x80\xa6";  // …
            return true;
        }
        const auto c = static_cast<unsigned char>(text[i]);
        ++chars;
        if (c < 0x80) {
            switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            case '\t': out += '\t'; break;
            default:
                if (c < 0x20 || c == 0x7f) append_hex_escape(out, c);
                else out += static_cast<char>(c);
            }
            ++i;
            continue;
        }
        const std::size_t len = utf8_sequence(text, i);
        if (len == 0) {
            append_hex_escape(out, c);
            ++i;
        } else {
            out.append(text.substr(i, len));
            i += len;
        }
    }
    return false;
}

std::string esc(std::string_view text) {
    std::string out;
    append_escaped(out, text);
    return out;
}

std::string fixed(double value, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
    std::string s = buf;
    if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
    return s;
}

std::string exact(double value) {
    char buf[64];
    for (int precision = 6; precision <= 17; ++precision) {
        std::snprintf(buf, sizeof buf, "%.*g", precision, value);
        if (std::strtod(buf, nullptr) == value) break;
    }
    return buf;
}

std::string seconds_text(double seconds) { return fixed(seconds, 6) + " s"; }

double to_seconds(Cycle cycle, std::uint32_t clock_hz) {
    return clock_hz == 0 ? 0.0 : static_cast<double>(cycle) / static_cast<double>(clock_hz);
}

}  // namespace avrbench::html_report
