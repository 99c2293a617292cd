// The motion oracle: compares where the machine's axes (and its pen) went
// with the path the accepted commands describe (parts/CommandedMoves.hpp),
// and reports what a person holding the drawing would see:
//
// - path-deviation: the tool strayed from the commanded line or arc by more
//   than `path_tolerance` (one finding per move, recorded when it first
//   strays, its text revised to the worst point as it grows);
// - move-end-missed: the tool left a move without reaching its end, or came
//   to rest (no carriage move for `rest_time`, or at the end of the run)
//   away from the end of the last move it made, by more than one step on an
//   axis (`end_tolerance` overrides);
// - tool-down-off-path: the pen was down while it travelled (a rapid,
//   homing) away from every drawing move, with the length it drew.
//
// Ports `x`, `y`, `z` take linear axes' carriages (any subset: the axes a
// machine has), or `effector` a mechanism's tool point (a delta robot's, in
// its own frame); `tool` a pen's contact. Positions are the firmware's: the
// carriage minus the axis' zero, which is where the carriage stood at
// power-up (firmware count from there; less `start_x`... when the firmware
// starts elsewhere) unless `origin_x`... says otherwise, moves by G92 as the
// firmware does, and after G28 is `home_x`... (where the firmware's homing
// puts its zero; without it the oracle stops judging). An effector's frame
// is the firmware's unless `origin_x`... says otherwise.
//
// Moves are tracked with a cursor: the move the tool is on, advanced when
// its end was reached and the next move is as close, or when a later move
// (up to eight ahead) is closer by more than the tolerance. A G0 is a
// straight line unless `rapids: any` (a firmware whose rapids are dog-legs);
// a G1 likewise unless `feeds: any` (a mechanism that moves its joints, not
// its tool, in straight lines: then only where each move ends is judged).
// After a line the bench could not read (CommandedMoves::frame_lost) it stops
// judging what follows the moves before it.
#pragma once

#include <array>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "parts/Carriage.hpp"
#include "parts/CommandedMoves.hpp"
#include "parts/Effector.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ToolContact.hpp"

namespace avrbench {

class MotionOracle final : public Part, public CommandedMoves {
public:
    static const FindingKind kPathDeviation;    // path-deviation
    static const FindingKind kMoveEndMissed;    // move-end-missed
    static const FindingKind kToolDownOffPath;  // tool-down-off-path
    static std::vector<ParamSpec> param_specs();
    // It reads carriages on any MCU's side of a board and drives nothing.
    static constexpr bool kObserver = true;

    MotionOracle(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "motion_oracle"; }
    void start() override;
    std::string summary() override;
    std::vector<Finding> pending_findings() const override;
    // An accepted move the machine is making or has not begun: the run is
    // not done. A move begun and left short at rest is judged, not waited for.
    bool still_going(std::string* why) const override;
    // A judged move under way runs to its end: a path is judged whole.
    bool may_find_more_at_pace(double seconds) override {
        (void)seconds;
        return still_going(nullptr);
    }

    void commanded(const CommandedMove& move) override;
    void position_renamed(const AxisPositions& was_mm, const AxisPositions& now_mm) override;
    void frame_lost(const std::string& line, const std::string& why) override;
    void stop_now(const std::string& line, const std::string& why) override;
    bool retract(std::size_t moves, bool stop_after) override;
    AxisPositions power_up_mm() const override { return start_mm_; }
    SoftLimits soft_limits_mm() const override { return soft_limits_mm_; }
    void job_answered_by(std::function<bool()> all_answered) override { job_answered_ = std::move(all_answered); }
    void dwell() override { dwell_pending_ = true; }
    void judged_elsewhere(const std::string& line) override;
    bool frame_restored() override;

    // For tests and front ends: moves judged so far, and whether judging stopped.
    std::size_t moves_judged() const { return moves_judged_now(); }
    bool judging() const { return !lost_; }

private:
    // A move in carriage coordinates (mm; axes without a carriage are 0).
    struct Tracked {
        CommandedMove::Kind kind = CommandedMove::Kind::Feed;
        std::string line;
        // Which commanded() call (a Z-first line makes two moves of one); a
        // barrier: how many had been made when judging stopped.
        std::uint64_t command = 0;
        bool barrier = false;  // after a lost frame: absorbs all motion, never ends
        bool barrier_by_move = false;  // made by the oracle on move `command - 1`
        bool free = false;     // its path is not judged (a rapid on `rapids: any`, homing)
        Eigen::Vector3d from = Eigen::Vector3d::Zero(), to = Eigen::Vector3d::Zero();
        Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // carriage = firmware + origin
        Eigen::Vector3d end_tolerance = Eigen::Vector3d::Zero();
        // Arcs, in XY: centre, radius, start angle and the signed sweep (rad).
        Eigen::Vector2d centre = Eigen::Vector2d::Zero();
        double radius = 0, start_rad = 0, sweep_rad = 0;
        double length = 0;     // mm along the path
        // How far the tool may stray: the board's path_tolerance, the
        // machine's step quantum and, for an arc, the firmware's chords.
        double tolerance = 0;
        // What the tool did on it.
        double progress = 0;   // mm along the path, as far as it came
        bool end_reached = false;
        double closest_end = 1e300;
        Eigen::Vector3d closest_at = Eigen::Vector3d::Zero();
        double worst = 0;
        Eigen::Vector3d worst_at = Eigen::Vector3d::Zero();
        Cycle worst_cycle = 0;
        double tool_off_mm = 0;
        Eigen::Vector3d tool_off_from = Eigen::Vector3d::Zero();
        Cycle tool_off_cycle = 0;
        bool rest_reported = false;
        bool after_dwell = false;  // a G4 came before it: it may still be waiting when a run ends
        bool unreachable = false;  // another part found the machine cannot make it
        // How long the machine may stand between steps on this move and still
        // be moving: rest_time, or longer for a slow feed.
        Cycle rest_cycles = 0;
        // Findings recorded when the fault began, revised as it grows.
        std::optional<std::size_t> deviation_finding, tool_finding;
        double deviation_told = 0, tool_told = 0;
        bool drawing() const;
    };

    bool connected(std::size_t axis) const { return effector_ != nullptr || carriages_[axis] != nullptr; }
    Eigen::Vector3d tool_position() const;
    void on_carriage();
    void arm_rest_check();
    // The rest time in force: the cursor's move's, else rest_time.
    Cycle rest_cycles_now() const;
    void on_rest_check();
    // Distance from p to the move's path (0 for free moves and barriers),
    // and how far along it p is (mm).
    double distance(const Tracked& m, const Eigen::Vector3d& p, double* along = nullptr) const;
    void advance(const Eigen::Vector3d& p);
    void observe(Tracked& m, const Eigen::Vector3d& p, Cycle now);
    void check_tool(const Eigen::Vector3d& p, Cycle now);
    // Records a finding the first time, rewrites its text after.
    void tell(std::optional<std::size_t>& finding, FindingKind kind, std::string detail);
    std::string seconds_text(Cycle cycle) const;
    std::string deviation_text(const Tracked& m) const;
    std::string tool_text(const Tracked& m) const;
    void finish_front(Cycle now);
    // The findings a move earned when the tool left it.
    std::vector<Finding> verdict(const Tracked& m, Cycle now) const;
    std::optional<Finding> rest_verdict(const Eigen::Vector3d& p, Cycle now) const;
    // At the end of a run whose job was all answered, with the machine at
    // rest: the first move it never made (and how many more), if any.
    std::optional<Finding> unmade_verdict(const Eigen::Vector3d& p, Cycle now) const;
    // Moves left behind by the cursor, and those judged where they stand.
    std::size_t moves_judged_now() const;
    bool ends_within(const Tracked& m, const Eigen::Vector3d& p, const Eigen::Vector3d& target) const;
    Finding make_finding(FindingKind kind, Cycle cycle, std::string detail) const;
    std::string firmware_text(const Tracked& m, const Eigen::Vector3d& carriage_mm) const;
    void lose(const std::string& why, bool by_move = false);
    // Where a homed axis came to rest (see settle_homes).
    void settle_homes(const Eigen::Vector3d& p);

    std::array<Carriage*, 3> carriages_{};
    Effector* effector_ = nullptr;
    std::function<bool()> job_answered_;
    bool dwell_pending_ = false;  // a G4 since the last move commanded
    ToolContact* tool_ = nullptr;
    double path_tolerance_mm_;
    double step_quantum_mm_ = 0;  // the diagonal of one step on every axis: a DDA's worst distance from a line
    std::optional<double> end_tolerance_mm_;
    bool rapids_straight_;
    bool feeds_straight_;
    AxisPositions start_mm_{0.0, 0.0, 0.0};
    SoftLimits soft_limits_mm_{};
    bool z_before_xy_;
    Cycle rest_cycles_;
    std::array<std::optional<double>, 3> origin_given_mm_{};
    std::array<std::optional<double>, 3> home_mm_{};
    std::string no_home_because_;  // the board's reason for giving no home
    std::array<std::optional<double>, 3> origin_mm_{};  // the firmware's zero on each carriage
    // A homed axis whose zero is taken where homing left it: a firmware
    // stops a step or two past the switch (Marlin 1.0 wants two readings in
    // a row), and calls that 0. Until a later straight move carries the axis
    // clearly away, `turn_mm` is the last place it reached moving towards
    // the switch.
    struct HomeSettle {
        std::uint64_t home_command = 0;  // the G28's move
        double home_mm = 0;              // where home_x puts the switch's 0 (carriage mm)
        double approach_sign = 0;        // +1 or -1: the direction the carriage homed in
        double turn_mm = 0;
    };
    std::array<std::optional<HomeSettle>, 3> settling_{};
    std::deque<Tracked> moves_;  // the cursor's move first
    std::optional<Tracked> last_drawing_;  // the last drawing move the cursor left
    Eigen::Vector3d last_position_ = Eigen::Vector3d::Zero();
    Cycle last_move_cycle_ = 0;     // when the tool last left rest_anchor_
    Eigen::Vector3d rest_anchor_ = Eigen::Vector3d::Zero();
    double rest_jitter_mm_ = 0;     // half the finest step: less is a rotor settling
    bool rest_check_armed_ = false;
    bool rest_judged_ = true;  // the current rest was judged (nothing moved since)
    bool lost_ = false;
    std::string lost_why_;
    std::size_t moves_judged_ = 0;
    std::uint64_t commands_ = 0;  // commanded() calls kept
};

}  // namespace avrbench
