// Findings of the firmware fuzz target, by root cause (shared by the target,
// bench/fuzz/fuzz_firmware.cpp, and the campaign, bench/fuzz/Campaign.cpp).
#pragma once

#include <algorithm>
#include <cctype>
#include <set>
#include <string>

namespace avrbench {

namespace fuzz_findings_detail {

// The shape of a G-code line: its command, the first word's letter and,
// for a command letter (G, M, T), its whole number of up to four digits
// ("G3S1Y1I0J2" -> "G3", "N5 M104 S200" -> "M104", "G X1" -> "G",
// "G69661" -> "G", "X65090 Y1" -> "X"): the lines one root cause answers to
// differ in their arguments, and a fuzzer varies those without end (a
// campaign on grbl_stepper told 69 "root causes" apart by an axis word's
// number).
inline std::string line_shape(const std::string& line) {
    std::size_t i = 0;
    const auto skip_blanks = [&] {
        while (i < line.size() && line[i] == ' ') ++i;
    };
    skip_blanks();
    // A line number first ("N12 G1 X5") is not the command.
    if (i < line.size() && std::toupper(static_cast<unsigned char>(line[i])) == 'N') {
        ++i;
        while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i]))) ++i;
        skip_blanks();
    }
    if (i >= line.size() || !std::isalpha(static_cast<unsigned char>(line[i]))) return "no command";
    const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(line[i++])));
    std::string shape(1, letter);
    if (letter != 'G' && letter != 'M' && letter != 'T') return shape;
    while (i < line.size() && line[i] == '0' && i + 1 < line.size() && std::isdigit(static_cast<unsigned char>(line[i + 1]))) ++i;
    std::string number;
    while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i]))) number.push_back(line[i++]);
    constexpr std::size_t kLongestCode = 4;  // M7219 is Marlin's longest; no firmware has a five-digit code
    return number.size() <= kLongestCode ? shape + number : shape;
}

// "sym+0x1c" -> "sym"; "0x1234" stays.
inline std::string function_of(std::string symbol) {
    const auto plus = symbol.find("+0x");
    if (plus != std::string::npos && plus > 0) symbol.erase(plus);
    while (!symbol.empty() && (symbol.back() == ' ' || symbol.back() == ')')) symbol.pop_back();
    return symbol;
}

}  // namespace fuzz_findings_detail

// "avrbench fuzz: FINDING after 28672 AVR instructions: <what>" -> its root
// cause, what one distinct finding is:
//   a crash (a finding with a PC)     source: kind in <function>, the PC's
//                                     function without its offset (a stack
//                                     overflow anywhere in __vector_11 is one);
//                                     a jump into nowhere: where it came from
//   a finding about a G-code line     source: kind on '<shape>' lines (the
//                                     line's command: G1, M104)
//   a delta's target-out-of-reach     source: kind: which limit ("arm 2
//                                     beyond its servo's travel")
//   a host event (timeout, fatal)     kind on '<shape>' lines
//   anything else                     source: kind
inline std::string finding_root_cause(std::string text) {
    using namespace fuzz_findings_detail;
    const auto colon = text.find("instructions: ");
    if (colon != std::string::npos) text.erase(0, colon + 14);
    // "<source>: <kind> at ... " or a host event "<kind>: <message>".
    const auto first = text.find(": ");
    if (first == std::string::npos) return text;
    const std::string head = text.substr(0, first);
    std::string rest = text.substr(first + 2);
    std::size_t kind_end = rest.find_first_of(" :,");
    if (kind_end == std::string::npos) kind_end = rest.size();
    static const std::set<std::string> kHostEvents = {"timeout", "fatal",   "hang",      "error",          "alarm",
                                                      "restarted", "resend-loop", "banner-timeout", "line-too-long"};
    const bool host_event = kHostEvents.count(head) != 0;
    const std::string kind = host_event ? head : rest.substr(0, kind_end);
    const std::string who = host_event ? "" : head + ": ";
    if (const auto from = rest.find("came from "); from != std::string::npos && kind == "pc-outside-program") {
        return who + kind + " from " + function_of(rest.substr(from + 10, rest.find_first_of(";:", from + 10) - (from + 10)));
    }
    if (const auto pc = rest.find(", PC 0x"); pc != std::string::npos) {
        std::size_t sym = rest.find(' ', pc + 7);
        std::string symbol = sym == std::string::npos ? "" : rest.substr(sym + 1);
        symbol = symbol.substr(0, symbol.find(": "));
        return who + kind + " in " + (symbol.empty() ? rest.substr(pc + 5, rest.find_first_of(" :", pc + 5) - (pc + 5)) : function_of(symbol));
    }
    if (kind == "target-out-of-reach") {
        const auto detail = rest.find("): ");
        const std::string what = detail == std::string::npos ? "" : rest.substr(detail + 3, rest.find("; ", detail) - (detail + 3));
        return who + kind + (what.empty() ? "" : ": " + what);
    }
    // The first quoted line: "line 7 'G1 X5'" (cut long ones: "'G92 X0...' (129 bytes)").
    const auto line = rest.find("line ");
    if (line != std::string::npos) {
        const auto open = rest.find('\'', line);
        const auto close = open == std::string::npos ? std::string::npos : rest.find('\'', open + 1);
        if (close != std::string::npos) return who + kind + " on '" + line_shape(rest.substr(open + 1, close - open - 1)) + "' lines";
    }
    return who + kind;
}

}  // namespace avrbench
