// What a part that judges the machine's motion is told about the motion the
// firmware was commanded: the moves of the lines it accepted, in the
// firmware's own coordinates (mm), in the order it accepted them. The bench
// reads them from a host's G-code (run/CommandedPath) or from the program
// a record job was made from, and hands them to every part with this
// interface (parts/MotionOracle), without knowing its type.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>

namespace avrbench {

// X, Y, Z in the firmware's coordinates (mm); an axis the bench cannot know
// (a line it could not read, a relative move from an unknown place) is empty.
using AxisPositions = std::array<std::optional<double>, 3>;

// How a firmware draws an arc: straight segments whose chords stray from
// the circle by at most `tolerance_mm` (grbl's $12 arc_tolerance), or
// segments `segment_mm` long (Marlin's MM_PER_ARC_SEGMENT); 0: exact.
struct ArcRule {
    double tolerance_mm = 0;
    double segment_mm = 0;
};

struct CommandedMove {
    enum class Kind {
        Rapid,            // G0: travel, the tool lifted
        Feed,             // G1: a straight line, the tool working
        ArcClockwise,     // G2, in the XY plane about `centre_mm`
        ArcCounterClockwise,  // G3
        Home,             // G28: to the firmware's zero on the axes `to_mm` names, by switches
    };
    Kind kind = Kind::Feed;
    AxisPositions from_mm{};
    AxisPositions to_mm{};
    std::array<double, 2> centre_mm{};  // arcs: X, Y of the centre
    ArcRule arc_rule;                   // arcs: how the firmware draws them
    // G1-G3: the feed the line asks for (its own F or the last one), if any.
    std::optional<double> feed_mm_per_min;
    std::array<bool, 3> homed{};        // Home: the axes it homes
    std::string line;                   // "line 7 'G2 X60 Y50 I0 J-10'", for findings
};

class CommandedMoves {
public:
    virtual ~CommandedMoves() = default;
    // The next move the firmware accepted.
    virtual void commanded(const CommandedMove& move) = 0;
    // The firmware calls its position on these axes something else from
    // here on (G92): axis k was `was_mm[k]` (empty: unknown) and is now
    // `now_mm[k]`; axes with an empty `now_mm` keep their frame.
    virtual void position_renamed(const AxisPositions& was_mm, const AxisPositions& now_mm) = 0;
    // From here on the bench cannot tell what the firmware's coordinates
    // mean (a line it could not read, a work offset, a G code it does not
    // model): stop judging until the end of the run.
    // `why` says what about the line (default: its meaning differs between
    // firmware).
    virtual void frame_lost(const std::string& line, const std::string& why = "means different things to different firmware") = 0;
    // From this moment the machine may stop anywhere, even on a move it is
    // making or has queued (grbl's feed hold '!', its reset, its overrides,
    // picked out of the stream as they arrive): stop judging, those moves
    // included. Default: as frame_lost.
    virtual void stop_now(const std::string& line, const std::string& why) { frame_lost(line, why); }
    // The firmware refused the line that gave the last `moves` moves (they
    // were told as the line went out, with the lines sent after it): forget
    // them. `stop_after`: reading the refused line or one after it stopped
    // the judging (frame_lost); that stop goes too, as does one the judge
    // made itself on those moves - the bench reads the later lines again,
    // and a stop comes back if its line does. False when it cannot, because
    // the machine began one (the bench then loses the frame).
    virtual bool retract(std::size_t moves, bool stop_after) = 0;
    // The firmware's software endstops, per axis (low, high; either may be
    // absent), in its coordinates: it clamps a line's end to them (Marlin's
    // and Repetier's MIN/MAX_SOFTWARE_ENDSTOPS). None by default.
    using SoftLimits = std::array<std::array<std::optional<double>, 2>, 3>;
    virtual SoftLimits soft_limits_mm() const { return {}; }
    // Where the firmware's own position is at power-up, in its coordinates:
    // 0 for firmware that counts from where the machine starts; a firmware
    // with another modal default (seed 004's delta: Z -310) says so.
    virtual AxisPositions power_up_mm() const { return {0.0, 0.0, 0.0}; }
    // The firmware waits here (G4) before the moves that follow.
    virtual void dwell() {}
    // The line that made the judge stop (frame_lost) was refused by the
    // firmware: its coordinates mean what they meant, judging goes on (true
    // also when the retract of that line already undid the stop). False
    // when it cannot (anything came after the stop).
    virtual bool frame_restored() { return false; }
    // Another part judged the move of line `line` (quoted as in
    // CommandedMove::line): the machine cannot make it (a delta's
    // target-out-of-reach). Nobody waits for it to begin.
    virtual void judged_elsewhere(const std::string& line) { (void)line; }
    // How the judge can tell that the firmware has answered every line the
    // job sent (its host is done): moves still waiting then were, for the
    // firmware, made or queued, so a machine at rest at the end has not made
    // them. Given once by the bench that runs the job.
    virtual void job_answered_by(std::function<bool()> all_answered) { (void)all_answered; }
};

}  // namespace avrbench
