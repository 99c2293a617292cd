// The one G-code reader of the bench: a line split into words (a letter and
// its number), under one of two sets of rules, strict or lenient.
//
//  - Strict: what every firmware family reads the same way, so that a judge
//    may hold the firmware to it: uppercase letters A-Z, each followed by an
//    optional sign and digits with an optional fraction (at least one
//    digit), words separated by spaces or touching ("G1X10"), an optional
//    "*checksum" of digits at the end. Any other byte (a comment, a
//    lowercase letter, an exponent, a letter without a number) makes the
//    line not strict: no words at all.
//  - Lenient: what a host needs to know about a line it sends (is it a
//    dwell, a heating wait, a temperature target): every letter followed by
//    a number strtod reads, upper-cased, anything between them skipped; the
//    words end at a comment (';' or '(') or a checksum ('*').
//
// The host (stimulus/UartHost), the motion judges (stimulus/CommandedTarget,
// run/CommandedPath), the heat targets (run/HeatTargets) and the CAM's
// records (cam/Records) read G-code through it.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

namespace avrbench {

struct GcodeWord {
    char letter;             // 'A'..'Z'
    double value;            // may be infinite under Lenient rules (400 digits)
    std::size_t begin, end;  // the word's bytes in the line: [begin, end)
};

// The words in their order; repeated letters are all returned (what a
// repeat means is the caller's). Strict: nothing when the line is not strict.
std::optional<std::vector<GcodeWord>> lex_strict_gcode(std::string_view line);
std::vector<GcodeWord> lex_lenient_gcode(std::string_view line);

// Lenient words as letter (upper case) -> number, the first finite one of
// each letter: "M104 S200 T1".
std::map<char, double> gcode_words(std::string_view line);

// The first word with `letter`, or nullptr.
const GcodeWord* find_word(const std::vector<GcodeWord>& words, char letter);

}  // namespace avrbench
