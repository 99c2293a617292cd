#include "stimulus/CommandedTarget.hpp"

#include <cstdlib>
#include <map>
#include <string>

namespace avrbench {
namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

}  // namespace

std::optional<std::map<char, double>> strict_gcode_words(std::string_view line, std::vector<double>* g_words) {
    if (const auto star = line.find('*'); star != std::string_view::npos) {
        const auto checksum = line.substr(star + 1);
        if (checksum.empty()) return std::nullopt;
        for (char c : checksum) {
            if (!is_digit(c)) return std::nullopt;
        }
        line = line.substr(0, star);
    }
    std::map<char, double> words;
    std::size_t i = 0;
    while (i < line.size()) {
        const char letter = line[i];
        if (letter == ' ') {
            ++i;
            continue;
        }
        if (letter < 'A' || letter > 'Z') return std::nullopt;
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
        if (j < line.size() && line[j] != ' ' && (line[j] < 'A' || line[j] > 'Z' || line[j] == 'E')) return std::nullopt;
        const double value = std::strtod(std::string(line.substr(i + 1, j - i - 1)).c_str(), nullptr);
        if (letter == 'G' && g_words != nullptr) {
            g_words->push_back(value);
        } else {
            if (words.count(letter) != 0) return std::nullopt;
            words[letter] = value;
        }
        i = j;
    }
    return words;
}

std::optional<std::array<double, 3>> CommandedTarget::accept(std::string_view line) {
    const auto words = strict_gcode_words(line);
    if (!words) {
        forget();
        return std::nullopt;
    }
    const auto g = words->find('G');
    bool move = false;
    if (g != words->end()) {
        const double code = g->second;
        if (code == 0 || code == 1) {
            move = true;
        } else if (code == 90) {
            relative_ = false;
        } else if (code == 91) {
            relative_ = true;
            forget();
        } else if (code == 21) {
            inches_ = false;
        } else if (code == 20) {
            inches_ = true;
            forget();
        } else if (code != 4) {  // G4 is a dwell; G28, G92, arcs, probing...: the position is unknown
            forget();
        }
    }
    static constexpr char kAxes[3] = {'X', 'Y', 'Z'};
    bool names_an_axis = false;
    for (std::size_t k = 0; k < 3; ++k) {
        const auto w = words->find(kAxes[k]);
        if (w == words->end()) continue;
        names_an_axis = true;
        if (move && !relative_ && !inches_) {
            xyz_mm_[k] = w->second;
        } else {
            xyz_mm_[k].reset();
        }
    }
    if (!move || relative_ || inches_ || !names_an_axis) return std::nullopt;
    if (!xyz_mm_[0] || !xyz_mm_[1] || !xyz_mm_[2]) return std::nullopt;
    return std::array<double, 3>{*xyz_mm_[0], *xyz_mm_[1], *xyz_mm_[2]};
}

}  // namespace avrbench
