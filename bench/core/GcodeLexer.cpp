#include "core/GcodeLexer.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>

namespace avrbench {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_upper(char c) { return c >= 'A' && c <= 'Z'; }

std::optional<std::vector<GcodeWord>> lex_strict(std::string_view line) {
    if (const auto star = line.find('*'); star != std::string_view::npos) {
        const auto checksum = line.substr(star + 1);
        if (checksum.empty()) return std::nullopt;
        for (char c : checksum) {
            if (!is_digit(c)) return std::nullopt;
        }
        line = line.substr(0, star);
    }
    std::vector<GcodeWord> words;
    std::size_t i = 0;
    while (i < line.size()) {
        const char letter = line[i];
        if (letter == ' ') {
            ++i;
            continue;
        }
        if (!is_upper(letter)) return std::nullopt;
        std::size_t j = i + 1;
        if (j < line.size() && (line[j] == '+' || line[j] == '-')) ++j;
        const std::size_t digits_from = j;
        while (j < line.size() && is_digit(line[j])) ++j;
        bool any_digit = j > digits_from;
        if (j < line.size() && line[j] == '.') {
            ++j;
            const std::size_t fraction_from = j;
            while (j < line.size() && is_digit(line[j])) ++j;
            any_digit = any_digit || j > fraction_from;
        }
        if (!any_digit) return std::nullopt;
        // A number must end at a space, the line's end or another word's
        // letter - never E (an exponent to atof/strtod) or anything else.
        if (j < line.size() && line[j] != ' ' && (!is_upper(line[j]) || line[j] == 'E')) return std::nullopt;
        const double value = std::strtod(std::string(line.substr(i + 1, j - i - 1)).c_str(), nullptr);
        words.push_back({letter, value, i, j});
        i = j;
    }
    return words;
}

std::vector<GcodeWord> lex_lenient(std::string_view line) {
    const std::string text(line);  // strtod needs the terminator
    std::vector<GcodeWord> words;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (c == ';' || c == '*' || c == '(') break;  // comment or checksum
        if (!std::isalpha(static_cast<unsigned char>(c))) continue;
        const char* begin = text.c_str() + i + 1;
        char* end = nullptr;
        const double value = std::strtod(begin, &end);
        if (end == begin) continue;
        const auto after = static_cast<std::size_t>(end - text.c_str());
        words.push_back({static_cast<char>(std::toupper(static_cast<unsigned char>(c))), value, i, after});
        i = after - 1;
    }
    return words;
}

}  // namespace

std::optional<std::vector<GcodeWord>> lex_strict_gcode(std::string_view line) { return lex_strict(line); }
std::vector<GcodeWord> lex_lenient_gcode(std::string_view line) { return lex_lenient(line); }

std::map<char, double> gcode_words(std::string_view line) {
    std::map<char, double> words;
    for (const GcodeWord& w : lex_lenient(line)) {
        if (std::isfinite(w.value)) words.emplace(w.letter, w.value);
    }
    return words;
}

const GcodeWord* find_word(const std::vector<GcodeWord>& words, char letter) {
    for (const GcodeWord& w : words) {
        if (w.letter == letter) return &w;
    }
    return nullptr;
}

}  // namespace avrbench
