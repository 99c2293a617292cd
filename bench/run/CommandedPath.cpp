#include "run/CommandedPath.hpp"

#include <cmath>
#include <vector>

#include "stimulus/CommandedTarget.hpp"

namespace avrbench {
namespace {

constexpr char kAxisLetters[3] = {'X', 'Y', 'Z'};

std::optional<double> word(const std::map<char, double>& words, char letter) {
    const auto it = words.find(letter);
    if (it == words.end()) return std::nullopt;
    return it->second;
}

}  // namespace

void CommandedPath::lose(const std::string& quoted) {
    if (lost_) return;
    lost_ = true;
    judge_->frame_lost(quoted);
}

void CommandedPath::lose(const std::string& quoted, const std::string& why) {
    if (lost_) return;
    lost_ = true;
    judge_->frame_lost(quoted, why);
}

bool CommandedPath::same_state(const CommandedPath& other) const {
    return position_mm_ == other.position_mm_ && relative_ == other.relative_ && mm_per_unit_ == other.mm_per_unit_ &&
           xy_plane_ == other.xy_plane_ && lost_ == other.lost_ && feed_mm_per_min_ == other.feed_mm_per_min_;
}

void CommandedPath::accept(std::string_view line, const std::string& quoted) {
    if (lost_) return;
    std::vector<double> g_words;
    const auto words = strict_gcode_words(line, &g_words);
    if (!words) return lose(quoted);
    for (const auto& [letter, value] : *words) {
        if (!std::isfinite(value)) return lose(quoted);  // 400 digits: strtod's infinity
    }
    std::array<std::optional<double>, 3> axis_words;
    bool names_an_axis = false;
    for (std::size_t k = 0; k < 3; ++k) {
        axis_words[k] = word(*words, kAxisLetters[k]);
        names_an_axis = names_an_axis || axis_words[k].has_value();
    }
    // The modal settings first (they apply to the line's own words), then
    // the one G word that uses the axis words.
    std::optional<int> axis_code;
    for (const double g : g_words) {
        if (g != std::floor(g) || g < 0 || g > 1000) return lose(quoted);
        const int code = static_cast<int>(g);
        switch (code) {
            case 4: judge_->dwell(); break;
            case 94: break;
            case 17: xy_plane_ = true; break;
            case 18:
            case 19: xy_plane_ = false; break;
            case 20: mm_per_unit_ = 25.4; break;
            case 21: mm_per_unit_ = 1.0; break;
            case 90: relative_ = false; break;
            case 91: relative_ = true; break;
            case 0:
            case 1:
            case 2:
            case 3:
            case 28:
            case 92:
                if (axis_code) return lose(quoted);  // two in a line: firmware differ
                axis_code = code;
                break;
            default: return lose(quoted);
        }
    }
    // F is modal, in the line's units per minute.
    if (const auto f = word(*words, 'F'); f && *f > 0) feed_mm_per_min_ = *f * mm_per_unit_;
    if (!axis_code) {
        if (names_an_axis) lose(quoted);  // modal motion (grbl moves, Marlin refuses), or a G4 with X
        return;
    }
    switch (*axis_code) {
        case 28: {
            CommandedMove home;
            home.kind = CommandedMove::Kind::Home;
            home.from_mm = position_mm_;
            home.to_mm = position_mm_;
            for (std::size_t k = 0; k < 3; ++k) {
                if (!axis_words[k] && names_an_axis) continue;
                home.to_mm[k] = 0.0;
                home.homed[k] = true;
            }
            home.line = quoted;
            position_mm_ = home.to_mm;
            ++moves_told_;
            judge_->commanded(home);
            return;
        }
        case 92: {
            if (!names_an_axis) return lose(quoted);
            AxisPositions was{}, now{};
            for (std::size_t k = 0; k < 3; ++k) {
                if (!axis_words[k]) continue;
                was[k] = position_mm_[k];
                now[k] = *axis_words[k] * mm_per_unit_;
                position_mm_[k] = now[k];
            }
            ++renames_told_;
            judge_->position_renamed(was, now);
            return;
        }
        default: {
            const double unit = mm_per_unit_;
            auto scaled = [unit](std::optional<double> v) -> std::optional<double> {
                if (!v) return std::nullopt;
                return *v * unit;
            };
            std::array<std::optional<double>, 3> words_mm;
            for (std::size_t k = 0; k < 3; ++k) words_mm[k] = scaled(axis_words[k]);
            move(*axis_code, words_mm, scaled(word(*words, 'I')), scaled(word(*words, 'J')), scaled(word(*words, 'R')),
                 quoted);
            return;
        }
    }
}

void CommandedPath::move(int code, const std::array<std::optional<double>, 3>& words_mm, std::optional<double> i_mm,
                         std::optional<double> j_mm, std::optional<double> r_mm, const std::string& quoted) {
    CommandedMove m;
    m.kind = code == 0   ? CommandedMove::Kind::Rapid
             : code == 1 ? CommandedMove::Kind::Feed
             : code == 2 ? CommandedMove::Kind::ArcClockwise
                         : CommandedMove::Kind::ArcCounterClockwise;
    m.line = quoted;
    m.arc_rule = arc_rule_;
    if (code != 0) m.feed_mm_per_min = feed_mm_per_min_;  // a rapid runs at the machine's own rate
    m.from_mm = position_mm_;
    for (std::size_t k = 0; k < 3; ++k) {
        if (!words_mm[k]) {
            m.to_mm[k] = position_mm_[k];
        } else if (!relative_) {
            m.to_mm[k] = words_mm[k];
        } else if (position_mm_[k]) {
            m.to_mm[k] = *position_mm_[k] + *words_mm[k];
        }
    }
    const bool arc = code == 2 || code == 3;
    if (arc) {
        if (!xy_plane_) return lose(quoted);
        const bool by_offsets = i_mm || j_mm;
        if (by_offsets == r_mm.has_value()) return lose(quoted);  // neither or both: firmware differ
        if (m.from_mm[0] && m.from_mm[1] && m.to_mm[0] && m.to_mm[1]) {
            const double x0 = *m.from_mm[0], y0 = *m.from_mm[1];
            if (by_offsets) {
                m.centre_mm = {x0 + i_mm.value_or(0.0), y0 + j_mm.value_or(0.0)};
            } else {
                // The centre at distance |R| from both ends: on the chord's
                // left for a counter-clockwise arc of at most 180 degrees, on
                // its right for a clockwise one; a negative R takes the
                // longer arc, the other side.
                const double dx = *m.to_mm[0] - x0, dy = *m.to_mm[1] - y0;
                const double chord = std::hypot(dx, dy);
                const double r = std::abs(*r_mm);
                const double h2 = r * r - chord * chord / 4.0;
                if (chord == 0 || h2 < -1e-9 * r * r) return lose(quoted);  // firmware differ on what they do
                double h = std::sqrt(std::max(0.0, h2));
                if ((code == 2) != (*r_mm < 0)) h = -h;
                m.centre_mm = {x0 + dx / 2 - h * dy / chord, y0 + dy / 2 + h * dx / chord};
            }
        }
    }
    position_mm_ = m.to_mm;
    bool moves = arc;  // an arc back to its start is a full circle
    for (std::size_t k = 0; k < 3; ++k) moves = moves || m.from_mm[k] != m.to_mm[k];
    if (moves) {
        ++moves_told_;
        judge_->commanded(m);
    }
}

}  // namespace avrbench
