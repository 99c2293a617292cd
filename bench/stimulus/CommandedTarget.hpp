// Where the G-code a firmware accepted has sent the machine, as far as the
// bench can tell for sure: the X, Y and Z of G0/G1 moves in absolute
// millimetres (G90, G21), one line at a time, the lines the firmware
// answered "ok" to.
//
// Firmware parse numbers their own way (our delta firmware's atof takes
// "X1E3" as 1000, a word inside a comment as a word), so a line is read only
// when every reading agrees: words of one upper-case letter and a plain
// decimal number ("X-12.5", "Y.5", "Z+3"), separated by spaces or nothing,
// each letter at most once, an optional leading N word and trailing
// "*checksum". Any other line forgets the axes (the firmware made something
// of it the bench cannot know), as do G91 (until G90 and new values), G20,
// G28, G92 and any other G word; a G0/G1 line in absolute millimetres sets
// the axes it names. A target is known once X, Y and Z all are.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

namespace avrbench {

// The words of a line in the strict form above (letter -> value, the N word
// included), or nothing when any byte is outside it. With `g_words`, G words
// go there in their order and may be several ("G21 G90"); without, a second
// G is outside the form like any repeated letter.
std::optional<std::map<char, double>> strict_gcode_words(std::string_view line, std::vector<double>* g_words = nullptr);

class CommandedTarget {
public:
    // A line the firmware answered "ok" to: the move's target (mm) when the
    // line is a G0/G1 move and all three axes are known, else nothing.
    std::optional<std::array<double, 3>> accept(std::string_view line);

private:
    void forget() { xyz_mm_ = {}; }

    std::array<std::optional<double>, 3> xyz_mm_{};
    bool relative_ = false;
    bool inches_ = false;
};

}  // namespace avrbench
