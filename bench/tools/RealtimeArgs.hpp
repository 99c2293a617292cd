// `--realtime TIME=BYTES` (repeatable), as `run` takes it.
#pragma once

#include <cctype>
#include <string>
#include <utility>

#include "core/Errors.hpp"
#include "core/Units.hpp"

namespace avrbench {

// "2.5s=!" / "1.5s=^X" / "3s=0x85": a time and the bytes to send then
// (printable characters as they are, ^X a control character, 0xNN any byte).
inline std::pair<Picoseconds, std::string> parse_realtime_bytes(const std::string& item, const char* option) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq + 1 >= item.size()) {
        throw BadInput(std::string(option) + " '" + item + "': expected TIME=BYTES, e.g. 2s=! or 1.5s=^X or 3s=0x85");
    }
    const Picoseconds at = parse_duration_ps(item.substr(0, eq), option);
    const std::string text = item.substr(eq + 1);
    std::string bytes;
    if (text.size() == 2 && text[0] == '^' && text[1] >= '@' && text[1] <= '_') {
        bytes.push_back(static_cast<char>(text[1] - '@'));
    } else if (text.size() == 4 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X') &&
               std::isxdigit(static_cast<unsigned char>(text[2])) && std::isxdigit(static_cast<unsigned char>(text[3]))) {
        bytes.push_back(static_cast<char>(std::stoi(text.substr(2), nullptr, 16)));
    } else {
        for (char c : text) {
            if (c < 0x20 || c > 0x7e) throw BadInput(std::string(option) + " '" + item + "': write control bytes as ^X or 0xNN");
        }
        bytes = text;
    }
    return {at, bytes};
}

}  // namespace avrbench
