#include "stimulus/GcodeMutator.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <random>

namespace avrbench {

namespace {

// Numbers that break naive parsers: overflow of 16/32-bit integers and of
// float, negative zero, long fractions, exponents, empty and lone signs.
const char* const kExtremeNumbers[] = {"1e9",          "-0",    "99999999999", "-99999999999", "2147483648",
                                       "-2147483649",  "65536", "32768",       "-32769",       "0.0000001",
                                       "1.7976931e308", "1e-40", "",            "-",            ".",
                                       "0x10",         "1..2",  "nan",         "inf",          "255.999999999"};

const char* const kLines[] = {"G0 X10 Y10",     "G1 X5 Y5 F600", "G1 X5 Y5",         "G2 X10 Y0 I5 J0 F300",
                              "G3 X0 Y0 I5 J5", "G28",           "G90",              "G91",
                              "G92 X0 Y0 Z0",   "G20",           "G21",              "G4 P100",
                              "M104 S200",      "M105",          "M109 S60",         "M114",
                              "M115",           "M400",          "M3 S1000",         "M5",
                              "G1 Z0.2 F100",   "G1 E5 F300",    "N1 G1 X1*52",      "$H",
                              "$X",             "?",             "G1 X-1000000 F9999"};

bool is_number_char(char c) { return std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+'; }

std::vector<std::string> split_lines(const std::string& text) {
    std::vector<std::string> lines;
    std::string current;
    for (char c : text) {
        if (c == '\n') {
            lines.push_back(current);
            current.clear();
        } else {
            current.push_back(c);
        }
    }
    if (!current.empty() || lines.empty()) lines.push_back(current);
    return lines;
}

std::string join_lines(const std::vector<std::string>& lines) {
    std::string out;
    for (const auto& l : lines) out += l + "\n";
    return out;
}

// Word boundaries: a word is a letter followed by a number.
std::vector<std::pair<std::size_t, std::size_t>> words_of(const std::string& line) {
    std::vector<std::pair<std::size_t, std::size_t>> words;
    for (std::size_t i = 0; i < line.size(); ++i) {
        if (!std::isalpha(static_cast<unsigned char>(line[i]))) continue;
        std::size_t j = i + 1;
        while (j < line.size() && is_number_char(line[j])) ++j;
        words.emplace_back(i, j);
        i = j - 1;
    }
    return words;
}

}  // namespace

const char* to_string(GcodeMutation mutation) {
    switch (mutation) {
        case GcodeMutation::ExtremeNumber: return "extreme number";
        case GcodeMutation::DropWord: return "drop word";
        case GcodeMutation::InsertWord: return "insert word";
        case GcodeMutation::NewLine: return "new line";
        case GcodeMutation::DuplicateLine: return "duplicate line";
        case GcodeMutation::OverlongLine: return "overlong line";
        case GcodeMutation::BinaryByte: return "binary byte";
        case GcodeMutation::DegenerateArc: return "degenerate arc";
        case GcodeMutation::NearbyNumber: return "nearby number";
        case GcodeMutation::ByteLevel: return "byte level";
    }
    return "?";
}

const std::vector<std::string>& gcode_dictionary() {
    static const std::vector<std::string> words = {
        "G0", "G1", "G2", "G3", "G4", "G17", "G20", "G21", "G28", "G90", "G91", "G92", "M3", "M5", "M82", "M84",
        "M104", "M105", "M106", "M109", "M110", "M114", "M115", "M140", "M190", "M400", "X", "Y", "Z", "E", "F",
        "I", "J", "K", "R", "S", "P", "N", "T", "*", ";", "(", ")", "$H", "$X", "$$", "?", "!", "~"};
    return words;
}

std::size_t mutate_gcode(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned seed,
                         ByteMutator byte_level, GcodeMutation* chosen) {
    std::mt19937 rng(seed);
    const auto pick = [&rng](std::size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
    const int kinds = byte_level != nullptr ? 10 : 9;
    auto mutation = static_cast<GcodeMutation>(pick(static_cast<std::size_t>(kinds)));
    if (chosen != nullptr) *chosen = mutation;
    if (mutation == GcodeMutation::ByteLevel) return byte_level(data, size, max_size);

    std::vector<std::string> lines = split_lines(std::string(reinterpret_cast<const char*>(data), size));
    std::string& line = lines[pick(lines.size())];
    const auto words = words_of(line);
    switch (mutation) {
        case GcodeMutation::ExtremeNumber: {
            const char* number = kExtremeNumbers[pick(std::size(kExtremeNumbers))];
            if (words.empty()) {
                line += std::string(" X") + number;
            } else {
                const auto [begin, end] = words[pick(words.size())];
                line.replace(begin + 1, end - begin - 1, number);
            }
            break;
        }
        case GcodeMutation::DropWord: {
            // Prefer the feed rate: a missing F is what seed 001's parser trips on.
            auto it = std::find_if(words.begin(), words.end(), [&line](const auto& w) { return line[w.first] == 'F'; });
            if (it == words.end() && !words.empty()) it = words.begin() + static_cast<long>(pick(words.size()));
            if (it != words.end()) line.erase(it->first, it->second - it->first);
            break;
        }
        case GcodeMutation::InsertWord: {
            const auto& dictionary = gcode_dictionary();
            std::string word = " " + dictionary[pick(dictionary.size())];
            if (std::isalpha(static_cast<unsigned char>(word.back()))) word += std::to_string(static_cast<int>(pick(2000)) - 500);
            line.insert(pick(line.size() + 1), word);
            break;
        }
        case GcodeMutation::NewLine:
            lines.insert(lines.begin() + static_cast<long>(pick(lines.size() + 1)), kLines[pick(std::size(kLines))]);
            break;
        case GcodeMutation::DuplicateLine: {
            const std::string copy = line;
            lines.insert(lines.begin() + static_cast<long>(pick(lines.size() + 1)), copy);
            break;
        }
        case GcodeMutation::OverlongLine: {
            const std::size_t target = 50 + pick(350);
            while (line.size() < target) line += " X" + std::to_string(pick(100000));
            break;
        }
        case GcodeMutation::BinaryByte: {
            const char byte = static_cast<char>(pick(256));
            line.insert(pick(line.size() + 1), 1, byte == '\n' ? '\0' : byte);
            break;
        }
        case GcodeMutation::DegenerateArc: {
            static const char* const kArcs[] = {"G2 X0 Y0 I0 J0", "G3 X0 Y0 I0 J0 F300", "G2 X10 Y10 I1e9 J0 F300",
                                                "G2 X10 Y0 R0 F300", "G3 X1 Y1 I0.0001 J0 F300", "G2 I-5 J0 F300"};
            line = kArcs[pick(std::size(kArcs))];
            break;
        }
        case GcodeMutation::NearbyNumber: {
            // Data bugs with no branch of their own (an unchecked table index
            // from a target just out of reach: seed 004) give coverage
            // nothing to follow; they need numbers of the right size. Each
            // word's number (at least one) is scaled by -4..4, shifted by up
            // to twice its magnitude (at least 100), or nudged by up to 10 %
            // and 5 units (limits lie just beyond the targets a job uses: the
            // delta's servo travel runs out 20 mm above seed 004's), and kept
            // whole: the target moves to somewhere near, in any direction.
            if (words.empty()) break;
            const std::size_t always = pick(words.size());
            for (std::size_t w = words.size(); w-- > 0;) {  // from the end: earlier offsets stay valid
                const bool also = pick(2) == 0;
                if (w != always && !also) continue;
                const auto [begin, end] = words[w];
                if (end - begin < 2) continue;
                const double value = std::atof(line.substr(begin + 1, end - begin - 1).c_str());
                const double magnitude = std::max(100.0, 2 * std::abs(value));
                double moved = value;
                switch (pick(3)) {
                    case 0: moved = value * (static_cast<double>(pick(81)) / 10.0 - 4.0); break;
                    case 1: moved = value + (static_cast<double>(pick(2001)) / 1000.0 - 1.0) * magnitude; break;
                    default:
                        moved = value * (1.0 + (static_cast<double>(pick(201)) / 1000.0 - 0.1)) +
                                (static_cast<double>(pick(11)) - 5.0);
                        break;
                }
                line.replace(begin + 1, end - begin - 1, std::to_string(static_cast<long>(moved)));
            }
            break;
        }
        case GcodeMutation::ByteLevel: break;
    }
    const std::string out = join_lines(lines);
    const std::size_t n = std::min(out.size(), max_size);
    std::copy(out.begin(), out.begin() + static_cast<long>(n), data);
    return n;
}

}  // namespace avrbench
