// The motion the G-code lines a firmware takes command, for the parts that
// judge it (parts/CommandedMoves.hpp): one line at a time, in the order the
// firmware receives them.
//
// Lines are read only where every firmware reads them alike (the strict
// words of stimulus/CommandedTarget: one upper-case letter and a plain
// decimal number per word, each letter once, optional N word and
// "*checksum"). Understood: G0/G1/G2/G3 (arcs in the XY plane by I/J or R),
// G4, G17, G20/G21, G90/G91, G94, G28 (home the named axes, all when none is
// named), G92 (rename the position), and words that do not move the machine
// (M, T, S, F, E, P...). With software endstops (CommandedMoves::
// soft_limits_mm) a line's end is clamped to them as Marlin does; an arc
// that crosses one, or a G92 (the endstops move with it as firmware
// differ), loses the frame. A line with axis words and no G (modal motion,
// which grbl takes and Marlin refuses), any other G word (work offsets,
// probing, G53, G28.1...) or a line outside the strict form loses the frame:
// nothing after it is judged.
#pragma once

#include <functional>
#include <string_view>

#include "parts/CommandedMoves.hpp"

namespace avrbench {

class CommandedPath {
public:
    explicit CommandedPath(CommandedMoves& judge)
        : judge_(&judge), position_mm_(judge.power_up_mm()), soft_limits_mm_(judge.soft_limits_mm()) {}
    // A line the firmware takes (the bench hands it over as it is sent, so a
    // firmware that answers after the move is followed while it moves);
    // `quoted` names it in findings.
    void accept(std::string_view line, const std::string& quoted);
    // Nothing after this line is judged (a refusal the judge cannot undo).
    void lose(const std::string& quoted);
    void lose(const std::string& quoted, const std::string& why);
    // From now the machine may stop anywhere, on the moves it is making too
    // (CommandedMoves::stop_now): nothing is judged from here.
    void stop_now(const std::string& quoted, const std::string& why);
    // How the firmware draws arcs (its family's: FirmwareArcs in run/Bench).
    void set_arc_rule(ArcRule rule) { arc_rule_ = rule; }

    // How many moves and renames the judge was told so far, and whether the
    // reading state (position, modes) is the same as another's: to undo a
    // line the firmware refused, a copy from before it is put back.
    std::size_t moves_told() const { return moves_told_; }
    std::size_t renames_told() const { return renames_told_; }
    bool lost() const { return lost_; }
    bool same_state(const CommandedPath& other) const;

private:
    void move(int code, const std::array<std::optional<double>, 3>& words_mm, std::optional<double> i_mm,
              std::optional<double> j_mm, std::optional<double> r_mm, const std::string& quoted);

    CommandedMoves* judge_;
    std::size_t moves_told_ = 0;
    std::size_t renames_told_ = 0;
    // Where the firmware is after the lines so far (from the judge's power_up_mm).
    AxisPositions position_mm_;
    bool relative_ = false;
    double mm_per_unit_ = 1.0;
    bool xy_plane_ = true;
    bool lost_ = false;
    std::optional<double> feed_mm_per_min_;
    ArcRule arc_rule_;
    CommandedMoves::SoftLimits soft_limits_mm_;  // the judge's: lines clamped to them
    bool any_soft_limit() const;
    // Whether an arc about `centre` from `from` to `to` (XY) reaches past an
    // X or Y software endstop anywhere on its way.
    bool arc_crosses_soft_limits(const CommandedMove& m) const;
};

}  // namespace avrbench
