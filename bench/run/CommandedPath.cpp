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

void CommandedPath::stop_now(const std::string& quoted, const std::string& why) {
    // Also when the reading was lost already: the moves before that still count.
    lost_ = true;
    judge_->stop_now(quoted, why);
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
            if (any_soft_limit()) return lose(quoted, "renames the position, and firmware move their software endstops with it in different ways");
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
    if (arc && arc_crosses_soft_limits(m)) {
        return lose(quoted, "is an arc that crosses the firmware's software endstops: firmware clamp or refuse it in different ways");
    }
    // Marlin's clamp_to_software_endstops: the line's end, axis by axis.
    for (std::size_t k = 0; k < 3 && !arc; ++k) {
        if (!m.to_mm[k]) continue;
        if (soft_limits_mm_[k][0]) m.to_mm[k] = std::max(*m.to_mm[k], *soft_limits_mm_[k][0]);
        if (soft_limits_mm_[k][1]) m.to_mm[k] = std::min(*m.to_mm[k], *soft_limits_mm_[k][1]);
    }
    position_mm_ = m.to_mm;
    bool moves = arc;  // an arc back to its start is a full circle
    for (std::size_t k = 0; k < 3; ++k) moves = moves || m.from_mm[k] != m.to_mm[k];
    if (moves) {
        ++moves_told_;
        judge_->commanded(m);
    }
}

bool CommandedPath::any_soft_limit() const {
    for (const auto& axis : soft_limits_mm_) {
        if (axis[0] || axis[1]) return true;
    }
    return false;
}

bool CommandedPath::arc_crosses_soft_limits(const CommandedMove& m) const {
    if (!any_soft_limit()) return false;
    if (!m.from_mm[0] || !m.from_mm[1] || !m.to_mm[0] || !m.to_mm[1]) return true;  // unknown: assume it does
    const double cx = m.centre_mm[0], cy = m.centre_mm[1];
    const double sx = *m.from_mm[0] - cx, sy = *m.from_mm[1] - cy;
    const double ex = *m.to_mm[0] - cx, ey = *m.to_mm[1] - cy;
    const double r = std::hypot(sx, sy);
    // The arc's X/Y extent: its ends, and the circle's extreme points at
    // 0, 90, 180 and 270 degrees where the sweep passes them.
    std::vector<std::array<double, 2>> points = {{*m.from_mm[0], *m.from_mm[1]}, {*m.to_mm[0], *m.to_mm[1]}};
    const double two_pi = 2 * std::acos(-1.0);
    auto wrap = [two_pi](double a) {
        a = std::fmod(a, two_pi);
        return a < 0 ? a + two_pi : a;
    };
    const bool ccw = m.kind == CommandedMove::Kind::ArcCounterClockwise;
    const double a0 = std::atan2(sy, sx), a1 = std::atan2(ey, ex);
    double sweep = ccw ? wrap(a1 - a0) : wrap(a0 - a1);
    if (sweep < 1e-12) sweep = two_pi;
    for (int q = 0; q < 4; ++q) {
        const double a = q * two_pi / 4;
        const double turned = ccw ? wrap(a - a0) : wrap(a0 - a);
        if (turned <= sweep) points.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
    }
    constexpr double kSlack_mm = 1e-9;
    for (const auto& p : points) {
        for (std::size_t k = 0; k < 2; ++k) {
            if (soft_limits_mm_[k][0] && p[k] < *soft_limits_mm_[k][0] - kSlack_mm) return true;
            if (soft_limits_mm_[k][1] && p[k] > *soft_limits_mm_[k][1] + kSlack_mm) return true;
        }
    }
    if (m.to_mm[2]) {
        if (soft_limits_mm_[2][0] && *m.to_mm[2] < *soft_limits_mm_[2][0]) return true;
        if (soft_limits_mm_[2][1] && *m.to_mm[2] > *soft_limits_mm_[2][1]) return true;
    }
    return false;
}

}  // namespace avrbench
