#include "stimulus/CommandedTarget.hpp"

#include <map>
#include <string>

#include "core/GcodeLexer.hpp"

namespace avrbench {

std::optional<std::map<char, double>> strict_gcode_words(std::string_view line, std::vector<double>* g_words) {
    const auto lexed = lex_strict_gcode(line);
    if (!lexed) return std::nullopt;
    std::map<char, double> words;
    for (const GcodeWord& w : *lexed) {
        if (w.letter == 'G' && g_words != nullptr) {
            g_words->push_back(w.value);
        } else {
            if (words.count(w.letter) != 0) return std::nullopt;
            words[w.letter] = w.value;
        }
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
