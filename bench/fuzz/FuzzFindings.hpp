// Findings of the firmware fuzz target, by kind (shared by the target,
// bench/fuzz/fuzz_firmware.cpp, and `avrbench fuzz`).
#pragma once

#include <cctype>
#include <string>

namespace avrbench {

// "avrbench fuzz: FINDING after 28672 AVR instructions: timeout: line 1 'G1 X5'
// got no answer within 1 s" -> "timeout: a line got no answer within 1 s":
// grouped by what happened, not by which line or when.
inline std::string finding_kind(std::string text) {
    const auto colon = text.find("instructions: ");
    if (colon != std::string::npos) text.erase(0, colon + 14);
    for (auto at = text.find("line "); at != std::string::npos; at = text.find("line ", at + 1)) {
        std::size_t i = at + 5;
        while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
        if (i == at + 5 || i + 1 >= text.size() || text[i] != ' ' || text[i + 1] != '\'') continue;
        auto close = text.find('\'', i + 2);
        if (close == std::string::npos) break;
        // A long line is shown cut, with its length: "'G92 X0...' (129 bytes)".
        if (text.compare(close + 1, 2, " (") == 0) {
            const auto bytes = text.find(" bytes)", close);
            if (bytes != std::string::npos && bytes < close + 16) close = bytes + 6;
        }
        text.replace(at, close + 1 - at, "a line");
    }
    // A jump into nowhere lands on a new PC each time: where it came from is
    // the finding ("pc-outside-program ... came from thesis_feed+0x30c").
    if (const auto jump = text.find(": pc-outside-program"); jump != std::string::npos) {
        const auto from = text.find("came from ");
        if (from != std::string::npos) return text.substr(0, jump) + ": pc-outside-program from " + text.substr(from + 10);
    }
    // A crash: "interp: simavr-crash, PC 0x40ca strcpy+0x8: <detail>" - the
    // place is the finding; the detail varies with the bytes written.
    if (const auto pc = text.find(", PC "); pc != std::string::npos) {
        const auto detail = text.find(": ", pc);
        if (detail != std::string::npos) text.erase(detail);
    }
    // A move the machine cannot make: which limit is the finding ("arm 2
    // beyond its servo's travel"); the line and target vary.
    if (const auto reach = text.find(": target-out-of-reach"); reach != std::string::npos) {
        const auto specifics = text.find("; ", reach);
        if (specifics != std::string::npos) text.erase(specifics);
    }
    // A finding's time and cycle: " at 1.200917 s (cycle 19214673)".
    const auto when = text.find(" s (cycle ");
    if (when != std::string::npos) {
        const auto start = text.rfind(" at ", when);
        const auto end = text.find(')', when);
        if (start != std::string::npos && end != std::string::npos) text.erase(start, end + 1 - start);
    }
    return text;
}

}  // namespace avrbench
