#include "parts/MotionOracle.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <utility>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"

namespace avrbench {

REGISTER_PART(MotionOracle, "motion_oracle");

const FindingKind MotionOracle::kPathDeviation = FindingKind::declare(
    "path-deviation", "the tool strayed from the commanded line or arc by more than the board's tolerance", Severity::Warning);
const FindingKind MotionOracle::kMoveEndMissed = FindingKind::declare(
    "move-end-missed", "the tool left a commanded move, or came to rest, away from the move's end", Severity::Warning);
const FindingKind MotionOracle::kToolDownOffPath = FindingKind::declare(
    "tool-down-off-path", "the pen was down while the machine travelled away from every drawing move", Severity::Warning);

namespace {

constexpr char kAxisLetters[3] = {'X', 'Y', 'Z'};
// Accepted moves the machine may be behind by before the oracle gives up
// (memory stays bounded on a firmware that acknowledges and never moves).
constexpr std::size_t kMaxPendingMoves = 4096;
// How many moves past the cursor a stray tool is compared with.
constexpr std::size_t kLookahead = 8;

double wrap_2pi(double rad) {
    double r = std::fmod(rad, 2 * std::numbers::pi);
    if (r < 0) r += 2 * std::numbers::pi;
    return r;
}

std::string mm_text(double mm) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3f", mm);
    return text;
}

}  // namespace

std::vector<ParamSpec> MotionOracle::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    std::vector<ParamSpec> specs = {
        {.name = "path_tolerance", .type = PT::Quantity, .dimension = D::Length, .default_value = "0.1mm",
         .source = "assumed: a few steps of a 80-160 steps/mm axis; a board with coarser timing states its own",
         .help = "how far the tool may stray from a commanded line or arc", .min = 1e-6, .max = 1.0},
        {.name = "end_tolerance", .type = PT::Quantity, .dimension = D::Length,
         .source = "default: one step of each axis (issue 40: end positions to one step)",
         .help = "how far from a move's end the tool may stop, per axis (default: one step)", .min = 0, .max = 1.0},
        {.name = "rapids", .type = PT::Choice, .default_value = "straight", .choices = {"straight", "any"},
         .source = "grbl, Marlin and Teacup move G0 on a straight line; a firmware that runs each axis at its own rate (seed 002) does not",
         .help = "whether a G0's path is judged (straight) or only its end (any)"},
        {.name = "feeds", .type = PT::Choice, .default_value = "straight", .choices = {"straight", "any"},
         .source = "a Cartesian machine moves G1-G3 on their paths; a delta whose firmware sets its servos' angles (seed 004) moves its joints, not its tool, in straight lines",
         .help = "whether the paths of G1-G3 are judged (straight) or only their ends (any)"},
        {.name = "z_moves", .type = PT::Choice, .default_value = "with_xy", .choices = {"with_xy", "before_xy"},
         .source = "with_xy: a line moves all its axes together; seed 001 (digest §3) moves Z alone first",
         .help = "how a line that changes Z and X/Y moves"},
        {.name = "rest_time", .type = PT::Quantity, .dimension = D::Time, .default_value = "200ms",
         .source = "assumed: longer than the step interval of any move but the slowest homing (5 steps/s)",
         .help = "how long no carriage moves before the machine counts as at rest"},
    };
    for (char axis : {'x', 'y', 'z'}) {
        const std::string a(1, axis);
        specs.push_back({.name = "origin_" + a, .type = PT::Quantity, .dimension = D::Length,
                         .source = "default: the carriage's position at power-up (firmware count from where they start)",
                         .help = "where the firmware's " + a + " = 0 is on the carriage (default: where it starts)",
                         .min = -10.0, .max = 10.0});
        specs.push_back({.name = "start_" + a, .type = PT::Quantity, .dimension = D::Length, .default_value = "0mm",
                         .source = "the firmware: the position it takes itself to be at before the first move (most: 0)",
                         .help = "the firmware's own " + a + " at power-up, in its coordinates", .min = -10.0, .max = 10.0});
        for (const char* end : {"min", "max"}) {
            specs.push_back({.name = "soft_" + std::string(end) + "_" + a, .type = PT::Quantity, .dimension = D::Length,
                             .source = "the firmware's configuration: Marlin's " + std::string(1, kAxisLetters[axis - 'x']) +
                                           "_" + (end[1] == 'i' ? "MIN" : "MAX") +
                                           "_POS with its software endstops on (Configuration.h), Repetier's likewise",
                             .help = "the firmware's software endstop, in its coordinates: it clamps a line's " + a +
                                     " to it, and an arc that crosses it is not judged (absent: none)",
                             .min = -10.0, .max = 10.0});
        }
        specs.push_back({.name = "home_" + a, .type = PT::Quantity, .dimension = D::Length,
                         .source = "the board: where the firmware's homing puts its zero (a switch's trip point)",
                         .help = "where " + a + " = 0 is on the carriage after G28 (absent: G28 ends judging)",
                         .min = -10.0, .max = 10.0});
    }
    specs.push_back({.name = "no_home_because", .type = PT::Text,
                     .source = "the board (board from-config writes the configuration line)",
                     .help = "why the board gives no home_x...: said when a G28 ends the judging"});
    return specs;
}

MotionOracle::MotionOracle(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    if (params.has("no_home_because")) no_home_because_ = hex_escaped(params.text("no_home_because"));  // text for a terminal
    path_tolerance_mm_ = params.quantity("path_tolerance") * 1e3;
    if (params.has("end_tolerance")) end_tolerance_mm_ = params.quantity("end_tolerance") * 1e3;
    rapids_straight_ = params.text("rapids") == "straight";
    feeds_straight_ = params.text("feeds") == "straight";
    z_before_xy_ = params.text("z_moves") == "before_xy";
    rest_cycles_ = std::max<Cycle>(1, clock.cycles_from_seconds(params.quantity("rest_time")));
    static constexpr const char* kAxes[3] = {"x", "y", "z"};
    for (std::size_t k = 0; k < 3; ++k) {
        const std::string a = kAxes[k];
        if (params.has("origin_" + a)) origin_given_mm_[k] = params.quantity("origin_" + a) * 1e3;
        start_mm_[k] = params.quantity("start_" + a) * 1e3;
        if (params.has("home_" + a)) home_mm_[k] = params.quantity("home_" + a) * 1e3;
        if (params.has("soft_min_" + a)) soft_limits_mm_[k][0] = params.quantity("soft_min_" + a) * 1e3;
        if (params.has("soft_max_" + a)) soft_limits_mm_[k][1] = params.quantity("soft_max_" + a) * 1e3;
        if (soft_limits_mm_[k][0] && soft_limits_mm_[k][1] && !(*soft_limits_mm_[k][0] < *soft_limits_mm_[k][1])) {
            throw part_error(this->name(), "soft_min_" + a + " must be below soft_max_" + a);
        }
        require_port<Carriage>(a, false, "the " + std::string(1, kAxisLetters[k]) + " axis' carriage",
                               [this, k](Carriage& c) {
                                   carriages_[k] = &c;
                                   c.on_move([this](double) { on_carriage(); });
                               });
    }
    require_port<Effector>("effector", false, "a mechanism's tool point (a delta_robot's effector), for x, y and z",
                           [this](Effector& e) {
                               effector_ = &e;
                               e.on_move([this](const Eigen::Vector3d&) { on_carriage(); });
                           });
    require_port<ToolContact>("tool", false, "the pen (a pen_lift's tool)", [this](ToolContact& t) { tool_ = &t; });
    add_readout("moves_judged", [this] { return static_cast<double>(moves_judged_now()); });
    add_readout("judging", [this] { return lost_ ? 0.0 : 1.0; });
}

void MotionOracle::start() {
    const bool any_carriage = carriages_[0] != nullptr || carriages_[1] != nullptr || carriages_[2] != nullptr;
    if (effector_ != nullptr && any_carriage) {
        throw part_error(name(), "join either the effector or the x, y, z carriages, not both");
    }
    if (effector_ == nullptr && !any_carriage) {
        throw part_error(name(), "join at least one of ports x, y, z to a linear axis' carriage, or effector to a mechanism's");
    }
    // An effector has no step to be exact to: the board says how close is there.
    if (effector_ != nullptr && !end_tolerance_mm_) {
        throw part_error(name(), "with an effector, give end_tolerance (how close the mechanism gets to a target)");
    }
    const Eigen::Vector3d power_up = tool_position();
    for (std::size_t k = 0; k < 3; ++k) {
        if (!connected(k)) continue;
        // A carriage's firmware zero: where it started, less where the
        // firmware thinks it started; an effector's frame is the firmware's.
        const double start_origin = effector_ != nullptr ? 0.0 : power_up[static_cast<Eigen::Index>(k)] - *start_mm_[k];
        origin_mm_[k] = origin_given_mm_[k] ? *origin_given_mm_[k] : start_origin;
    }
    last_position_ = power_up;
    rest_anchor_ = last_position_;
    last_move_cycle_ = clock().cycle();
    // Less than this is a rotor settling about its step, not motion; an
    // effector driven by servos stands still when it stands.
    double finest_step = effector_ != nullptr ? 2e-3 : 1e300;
    for (std::size_t k = 0; k < 3; ++k) {
        if (carriages_[k] != nullptr) finest_step = std::min(finest_step, carriages_[k]->step_mm());
    }
    rest_jitter_mm_ = finest_step / 2;
    // A step motor's carriage stands only on its step grid: every axis is up
    // to one step off the ideal line, so the tool up to the diagonal of one
    // step of each (grbl's 1/250 mm steps made 0.100-0.104 mm "deviations"
    // of a 0.1 mm tolerance). An effector (servos) has no grid.
    double quantum2 = 0;
    for (std::size_t k = 0; k < 3; ++k) {
        if (carriages_[k] != nullptr) quantum2 += carriages_[k]->step_mm() * carriages_[k]->step_mm();
    }
    step_quantum_mm_ = std::sqrt(quantum2);
}

namespace {

// How far a firmware's straight segments stray from a circle of radius r:
// the sagitta of one chord, r (1 - cos(theta / 2)) for a segment of angle
// theta = segment / r (at most half the circle), or its stated tolerance.
double chord_error_mm(const ArcRule& rule, double radius_mm) {
    double error = rule.tolerance_mm;
    if (rule.segment_mm > 0 && radius_mm > 0) {
        const double half_angle = std::min(std::numbers::pi / 2, rule.segment_mm / (2 * radius_mm));
        error = std::max(error, radius_mm * (1 - std::cos(half_angle)));
    }
    return error;
}

}  // namespace

bool MotionOracle::Tracked::drawing() const {
    return !barrier && (kind == CommandedMove::Kind::Feed || kind == CommandedMove::Kind::ArcClockwise ||
                        kind == CommandedMove::Kind::ArcCounterClockwise);
}

Eigen::Vector3d MotionOracle::tool_position() const {
    if (effector_ != nullptr) return effector_->effector_mm();
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k) {
        if (connected(k)) p[static_cast<Eigen::Index>(k)] = carriages_[k]->position_mm();
    }
    return p;
}

void MotionOracle::lose(const std::string& why, bool by_move) {
    if (lost_) return;
    lost_ = true;
    lost_why_ = why;
    Tracked barrier;
    barrier.barrier = true;
    barrier.command = commands_;
    barrier.barrier_by_move = by_move;
    moves_.push_back(barrier);
}

void MotionOracle::frame_lost(const std::string& line, const std::string& why) {
    lose(line + " " + why);
}

void MotionOracle::stop_now(const std::string& line, const std::string& why) {
    // The moves under way or queued may end anywhere: none is judged. What
    // the tool did until now was told already (a stray before the hold).
    moves_judged_ += static_cast<std::size_t>(std::count_if(moves_.begin(), moves_.end(), [](const Tracked& m) {
        return !m.barrier && (m.end_reached || m.progress > m.end_tolerance.maxCoeff());
    }));
    moves_.clear();
    lost_ = false;
    lose(line + " " + why);
}

void MotionOracle::position_renamed(const AxisPositions& was_mm, const AxisPositions& now_mm) {
    if (lost_) return;
    for (std::size_t k = 0; k < 3; ++k) {
        if (!now_mm[k] || !connected(k)) continue;
        if (!was_mm[k] || !origin_mm_[k]) return lose(std::string("G92 renames ") + kAxisLetters[k] + " from an unknown position");
        origin_mm_[k] = *origin_mm_[k] + *was_mm[k] - *now_mm[k];
    }
}

void MotionOracle::commanded(const CommandedMove& move) {
    // Numbered even when not kept (judging stopped): retract() counts the
    // moves of a refused line and those told after it, kept or not.
    const std::uint64_t command = commands_++;
    if (lost_) return;
    if (moves_.size() >= kMaxPendingMoves) return lose("the machine is more than 4096 accepted moves behind", true);
    Tracked t;
    t.kind = move.kind;
    t.line = move.line;
    t.command = command;
    t.after_dwell = std::exchange(dwell_pending_, false);
    const bool home = move.kind == CommandedMove::Kind::Home;
    t.free = home || (move.kind == CommandedMove::Kind::Rapid ? !rapids_straight_ : !feeds_straight_);
    for (std::size_t k = 0; k < 3; ++k) {
        if (!connected(k)) continue;
        const auto i = static_cast<Eigen::Index>(k);
        const double step = end_tolerance_mm_ ? *end_tolerance_mm_ : carriages_[k]->step_mm();  // (an effector: given)
        t.end_tolerance[i] = step + 1e-9;
        if (!origin_mm_[k] || !move.from_mm[k]) return lose(move.line + " starts where the bench cannot know", true);
        t.from[i] = *move.from_mm[k] + *origin_mm_[k];
        if (home && move.homed[k]) {
            origin_mm_[k] = home_mm_[k];
            if (!origin_mm_[k]) {
                return lose(move.line + " homes " + kAxisLetters[k] + " and the board gives no home_" +
                                static_cast<char>(kAxisLetters[k] - 'A' + 'a') +
                                (no_home_because_.empty() ? std::string() : " (" + no_home_because_ + ")"),
                            true);
            }
            // Where a switch trips is not a step-exact place.
            t.end_tolerance[i] = std::max(t.end_tolerance[i], path_tolerance_mm_);
        }
        if (!move.to_mm[k]) return lose(move.line + " ends where the bench cannot know", true);
        t.to[i] = *move.to_mm[k] + *origin_mm_[k];
        t.origin[i] = *origin_mm_[k];
        if (home && move.homed[k]) {
            const double approach = t.to[i] - t.from[i];
            settling_[k].reset();
            if (approach != 0) settling_[k] = HomeSettle{command, t.to[i], approach > 0 ? 1.0 : -1.0, t.from[i]};
        }
    }
    // A slow feed steps seldom: at F mm/min the carriage moving fastest does
    // at least F / sqrt(3) of it, a step every step_mm sqrt(3) / (F / 60) s;
    // the machine is at rest only after 2.5 times that without a step (the
    // bench's own factor: a decelerating step is up to 2.47 times the one
    // before, AVR446).
    t.rest_cycles = rest_cycles_;
    if (move.feed_mm_per_min && *move.feed_mm_per_min > 0 && effector_ == nullptr) {
        double largest_step = 0;
        for (std::size_t k = 0; k < 3; ++k) {
            if (carriages_[k] != nullptr) largest_step = std::max(largest_step, carriages_[k]->step_mm());
        }
        const double interval_s = largest_step * std::sqrt(3.0) / (*move.feed_mm_per_min / 60.0);
        constexpr double kLongestRest_s = 60.0;  // a step a minute is a machine standing still
        t.rest_cycles = std::max(rest_cycles_, clock().cycles_from_seconds(std::min(2.5 * interval_s, kLongestRest_s)));
    }
    const bool arc = move.kind == CommandedMove::Kind::ArcClockwise || move.kind == CommandedMove::Kind::ArcCounterClockwise;
    if (arc) {
        t.centre = {move.centre_mm[0] + t.origin[0], move.centre_mm[1] + t.origin[1]};
        const Eigen::Vector2d start = t.from.head<2>() - t.centre;
        const Eigen::Vector2d end = t.to.head<2>() - t.centre;
        t.radius = start.norm();
        if (t.radius < 1e-9) {
            t.kind = CommandedMove::Kind::Feed;  // no circle: the firmware moves straight, if at all
        } else {
            t.start_rad = std::atan2(start.y(), start.x());
            const double end_rad = std::atan2(end.y(), end.x());
            const bool ccw = move.kind == CommandedMove::Kind::ArcCounterClockwise;
            double sweep = ccw ? wrap_2pi(end_rad - t.start_rad) : wrap_2pi(t.start_rad - end_rad);
            if (sweep < 1e-9) sweep = 2 * std::numbers::pi;  // back to its start: a whole circle
            t.sweep_rad = ccw ? sweep : -sweep;
            t.length = std::hypot(sweep * t.radius, t.to.z() - t.from.z());
        }
    }
    if (!arc || t.kind == CommandedMove::Kind::Feed) t.length = (t.to - t.from).norm();
    t.tolerance = path_tolerance_mm_ + step_quantum_mm_ + (arc ? chord_error_mm(move.arc_rule, t.radius) : 0.0);
    if (arc) {
        // An arc whose end is off its circle has no one path: grbl refuses
        // it (gcode.c, error:33 past 0.005 mm and 0.1 % of the radius),
        // Marlin turns the start's radius through the angle and runs a line
        // to the end, and a radius of 0 is a line to some, nothing to others.
        const double end_radius = (t.to.head<2>() - t.centre).norm();
        if (std::abs(end_radius - t.radius) > t.tolerance) {
            return lose(move.line + " is an arc whose end is off its circle (radius " + mm_text(t.radius) + " mm at the start, " +
                            mm_text(end_radius) + " mm at the end): firmware draw it in different ways",
                        true);
        }
    }
    const bool z_and_xy = t.from.z() != t.to.z() && (t.from.head<2>() - t.to.head<2>()).norm() > 0;
    if (z_before_xy_ && z_and_xy && !arc && !home) {
        Tracked z_alone = t;
        z_alone.to.head<2>() = t.from.head<2>();
        z_alone.length = std::abs(t.to.z() - t.from.z());
        t.from.z() = t.to.z();
        t.length = (t.to - t.from).norm();
        moves_.push_back(z_alone);
    }
    moves_.push_back(t);
    // A firmware that answers once the move is done (seed 001's thesis
    // parser) is told of it when the tool already stands at its end: judge
    // the tool where it is now, as if it had just moved there.
    const Eigen::Vector3d p = tool_position();
    observe(moves_.front(), p, clock().cycle());
    advance(p);
}

bool MotionOracle::retract(std::size_t moves, bool stop_after) {
    if (moves > commands_) return false;
    const std::uint64_t first = commands_ - moves;
    // The refused line's moves are the last told, with those of the lines
    // after it. The stop in judging that one of them made goes too: the
    // grbl 1.1h campaign kept line 3 '0''s stop after refused line 1, so the
    // re-read line 2 'G1X1F5' was never told and line 4 was judged from
    // where line 2 should have taken the tool (docs/THIRD_PARTY.md).
    for (const Tracked& m : moves_) {
        if (m.barrier || m.command < first) continue;
        const bool begun = m.progress > m.end_tolerance.maxCoeff() || m.end_reached || m.deviation_finding || m.tool_finding;
        if (begun && &m == &moves_.front()) return false;
    }
    const auto taken_back = [first, stop_after](const Tracked& m) {
        if (!m.barrier) return m.command >= first;
        // Made on a move of those lines, or on reading one of them.
        return m.barrier_by_move ? m.command > first : stop_after && m.command >= first;
    };
    moves_.erase(std::remove_if(moves_.begin(), moves_.end(), taken_back), moves_.end());
    commands_ = first;
    if (lost_ && std::none_of(moves_.begin(), moves_.end(), [](const Tracked& m) { return m.barrier; })) {
        lost_ = false;
        lost_why_.clear();
    }
    return true;
}

double MotionOracle::distance(const Tracked& m, const Eigen::Vector3d& p, double* along) const {
    if (along != nullptr) *along = 0;
    if (m.barrier) return 0;
    if (m.free) {
        // Its path is any within the box its ends span (a dog-leg, a homing run).
        const Eigen::Vector3d low = m.from.cwiseMin(m.to), high = m.from.cwiseMax(m.to);
        return (p - p.cwiseMax(low).cwiseMin(high)).norm();
    }
    if (m.kind == CommandedMove::Kind::Feed || m.kind == CommandedMove::Kind::Rapid) {
        const Eigen::Vector3d d = m.to - m.from;
        const double len2 = d.squaredNorm();
        const double t = len2 > 0 ? std::clamp((p - m.from).dot(d) / len2, 0.0, 1.0) : 0.0;
        if (along != nullptr) *along = t * m.length;
        return (p - (m.from + t * d)).norm();
    }
    const Eigen::Vector2d v = p.head<2>() - m.centre;
    const double angle = std::atan2(v.y(), v.x());
    const double sweep = std::abs(m.sweep_rad);
    const double turned = m.sweep_rad > 0 ? wrap_2pi(angle - m.start_rad) : wrap_2pi(m.start_rad - angle);
    if (turned <= sweep) {
        const double fraction = turned / sweep;
        const double z = m.from.z() + fraction * (m.to.z() - m.from.z());
        if (along != nullptr) *along = fraction * m.length;
        return std::hypot(v.norm() - m.radius, p.z() - z);
    }
    const double to_start = (p - m.from).norm();
    const double to_end = (p - m.to).norm();
    if (along != nullptr && to_end < to_start) *along = m.length;
    return std::min(to_start, to_end);
}

bool MotionOracle::ends_within(const Tracked& m, const Eigen::Vector3d& p, const Eigen::Vector3d& target) const {
    return ((p - target).cwiseAbs().array() <= m.end_tolerance.array()).all();
}

void MotionOracle::observe(Tracked& m, const Eigen::Vector3d& p, Cycle now) {
    if (m.barrier) return;
    double along = 0;
    double d = distance(m, p, &along);
    // On the way from this move onto the next, a point is judged against
    // both: the cursor moves on only once the next is clearly closer.
    if (&m == &moves_.front() && moves_.size() >= 2) d = std::min(d, distance(moves_[1], p));
    if (!m.free && d > m.worst) {
        m.worst = d;
        m.worst_at = p;
        m.worst_cycle = now;
        // Told at once (a fuzzer's input ends at its first finding), then
        // again each time it grows by a micrometre.
        if (m.worst > m.tolerance && m.worst > m.deviation_told + 1e-3) {
            m.deviation_told = m.worst;
            tell(m.deviation_finding, kPathDeviation, deviation_text(m));
        }
    }
    // Progress only runs on along the path: a point just behind the start of
    // a whole circle is not its end.
    const double jump = 2 * path_tolerance_mm_ + 0.5;
    if (along > m.progress && along <= m.progress + jump) m.progress = along;
    const double to_end = (p - m.to).norm();
    if (to_end < m.closest_end) {
        m.closest_end = to_end;
        m.closest_at = p;
    }
    const double slack = path_tolerance_mm_ + m.end_tolerance.maxCoeff();
    if (ends_within(m, p, m.to) && (m.free || m.progress >= m.length - slack)) m.end_reached = true;
}

void MotionOracle::advance(const Eigen::Vector3d& p) {
    const Cycle now = clock().cycle();
    while (moves_.size() >= 2 && !moves_.front().barrier) {
        const Tracked& cur = moves_.front();
        const double here = distance(cur, p);
        std::size_t go = 0;
        // A free move's path is its whole box, which the next one's may lie
        // in (a delta's short moves): once its end was reached, the tool has
        // gone on when it stands within the next move's end, clearly nearer
        // to it than to this one's.
        const bool at_next_end = cur.free && cur.end_reached && ends_within(moves_[1], p, moves_[1].to) &&
                                 (p - moves_[1].to).norm() + path_tolerance_mm_ < (p - cur.to).norm();
        if (cur.end_reached && (distance(moves_[1], p) <= here + path_tolerance_mm_ || at_next_end)) {
            go = 1;
        } else {
            for (std::size_t j = 1; j < moves_.size() && j <= kLookahead; ++j) {
                if (distance(moves_[j], p) + path_tolerance_mm_ < here) {
                    go = j;
                    break;
                }
            }
        }
        if (go == 0) return;
        for (std::size_t i = 0; i < go; ++i) finish_front(now);
        Tracked& next = moves_.front();
        double along = 0;
        distance(next, p, &along);
        // A closed path (a whole circle) starts at its start, whatever the angle says.
        next.progress = (next.to - next.from).norm() <= next.end_tolerance.maxCoeff() ? 0.0 : along;
        observe(next, p, now);
    }
}

void MotionOracle::check_tool(const Eigen::Vector3d& p, Cycle now) {
    if (tool_ == nullptr || !tool_->tool_down() || moves_.empty()) return;
    Tracked& cur = moves_.front();
    if (cur.barrier || cur.drawing()) return;  // a drawing move: path-deviation judges it
    double nearest = last_drawing_ ? distance(*last_drawing_, p) : 1e300;
    for (std::size_t j = 1; j < moves_.size() && j <= kLookahead; ++j) {
        if (moves_[j].drawing()) {
            nearest = std::min(nearest, distance(moves_[j], p));
            break;
        }
    }
    if (nearest <= path_tolerance_mm_) return;
    if (cur.tool_off_mm == 0) {
        cur.tool_off_from = last_position_;
        cur.tool_off_cycle = now;
    }
    cur.tool_off_mm += (p - last_position_).norm();
    if (cur.tool_off_mm > path_tolerance_mm_ && cur.tool_off_mm > cur.tool_told + 1e-2) {
        cur.tool_told = cur.tool_off_mm;
        tell(cur.tool_finding, kToolDownOffPath, tool_text(cur));
    }
}

void MotionOracle::tell(std::optional<std::size_t>& finding, FindingKind kind, std::string detail) {
    if (finding) {
        revise_finding(*finding, std::move(detail));
    } else {
        finding = report(kind, std::move(detail));
    }
}

std::string MotionOracle::seconds_text(Cycle cycle) const {
    char at[48];
    std::snprintf(at, sizeof at, "%.6f s", static_cast<double>(cycle) / clock().frequency_hz());
    return at;
}

std::string MotionOracle::deviation_text(const Tracked& m) const {
    const bool arc = m.kind == CommandedMove::Kind::ArcClockwise || m.kind == CommandedMove::Kind::ArcCounterClockwise;
    return m.line + ": the tool strays " + mm_text(m.worst) + " mm from the commanded " + (arc ? "arc" : "line") +
           " (tolerance " + mm_text(m.tolerance) + " mm), at " + firmware_text(m, m.worst_at) + " at " +
           seconds_text(m.worst_cycle);
}

std::string MotionOracle::tool_text(const Tracked& m) const {
    return m.line + ": the pen was down for " + mm_text(m.tool_off_mm) + " mm of this move away from the drawing, from " +
           firmware_text(m, m.tool_off_from) + " at " + seconds_text(m.tool_off_cycle);
}

void MotionOracle::on_carriage() {
    const Eigen::Vector3d p = tool_position();
    const Cycle now = clock().cycle();
    // A rotor settling about its step (a fraction of one) is not motion.
    if ((p - rest_anchor_).cwiseAbs().maxCoeff() > rest_jitter_mm_) {
        rest_anchor_ = p;
        last_move_cycle_ = now;
        rest_judged_ = false;
        arm_rest_check();
    }
    settle_homes(p);
    if (!moves_.empty()) {
        observe(moves_.front(), p, now);
        advance(p);
        check_tool(p, now);
    }
    last_position_ = p;
}

// A homed axis' zero is where homing left it, if that is within
// path_tolerance of home_x...: the last place the carriage reached moving
// towards the switch, once the first straight move after the G28 that
// drives the axis carries it away by more than path_tolerance (a homing
// back-off before that move is the cursor's is not the end of homing; one
// taking the axis towards the switch leaves home_x as it is); for an axis
// the first move after the G28 leaves alone, where it stands once that move
// is path_tolerance under way. The moves told since the G28 move with it.
void MotionOracle::settle_homes(const Eigen::Vector3d& p) {
    for (std::size_t k = 0; k < 3; ++k) {
        if (!settling_[k]) continue;
        HomeSettle& s = *settling_[k];
        const auto i = static_cast<Eigen::Index>(k);
        if ((p[i] - last_position_[i]) * s.approach_sign > 0) s.turn_mm = p[i];
        if (moves_.empty() || lost_) continue;
        const Tracked& front = moves_.front();
        if (front.barrier || front.command <= s.home_command) continue;
        const double travel = front.to[i] - front.from[i];
        const bool straight = !front.free && (front.kind == CommandedMove::Kind::Feed || front.kind == CommandedMove::Kind::Rapid);
        double rest_mm = 0;
        if (travel == 0) {
            // An axis this move leaves alone rests where homing left it, once the move is under way.
            if (front.free || front.progress <= path_tolerance_mm_) continue;
            rest_mm = p[i];
        } else {
            if (!straight) continue;
            if (travel * s.approach_sign > 0) {
                settling_[k].reset();
                continue;
            }
            if ((s.turn_mm - p[i]) * s.approach_sign <= path_tolerance_mm_) continue;
            rest_mm = s.turn_mm;
        }
        const double shift = rest_mm - s.home_mm;
        settling_[k].reset();
        if (std::abs(shift) > path_tolerance_mm_ || shift == 0) continue;
        for (Tracked& m : moves_) {
            if (m.barrier || m.command <= s.home_command) continue;
            m.from[i] += shift;
            m.to[i] += shift;
            m.origin[i] += shift;
            if (k < 2) m.centre[i] += shift;
            m.closest_end = (m.closest_at - m.to).norm();
        }
        if (origin_mm_[k]) origin_mm_[k] = *origin_mm_[k] + shift;
    }
}

Cycle MotionOracle::rest_cycles_now() const {
    if (!moves_.empty() && !moves_.front().barrier) return moves_.front().rest_cycles;
    return rest_cycles_;
}

void MotionOracle::arm_rest_check() {
    if (rest_check_armed_) return;
    rest_check_armed_ = true;
    clock().scheduler().at(last_move_cycle_ + rest_cycles_now(), [this](Cycle) { on_rest_check(); });
}

void MotionOracle::on_rest_check() {
    rest_check_armed_ = false;
    const Cycle now = clock().cycle();
    if (now < last_move_cycle_ + rest_cycles_now()) return arm_rest_check();
    if (rest_judged_) return;
    rest_judged_ = true;
    if (auto f = rest_verdict(tool_position(), now)) {
        report(f->kind, f->detail);
        Tracked& cur = moves_.front();  // rest_verdict found one, so there is a move
        if (cur.progress > cur.end_tolerance.maxCoeff() || cur.end_reached) cur.rest_reported = true;
    }
}

std::string MotionOracle::firmware_text(const Tracked& m, const Eigen::Vector3d& carriage_mm) const {
    std::string text;
    for (std::size_t k = 0; k < 3; ++k) {
        if (!connected(k)) continue;
        const auto i = static_cast<Eigen::Index>(k);
        text += (text.empty() ? "" : " ") + std::string(1, kAxisLetters[k]) + mm_text(carriage_mm[i] - m.origin[i]);
    }
    return text;
}

Finding MotionOracle::make_finding(FindingKind kind, Cycle cycle, std::string detail) const {
    Finding f;
    f.kind = kind;
    f.source = name();
    f.cycle = cycle;
    f.clock_hz = clock().frequency_hz();
    f.has_pc = false;
    f.detail = std::move(detail);
    return f;
}

std::optional<Finding> MotionOracle::rest_verdict(const Eigen::Vector3d& p, Cycle now) const {
    if (moves_.empty() || moves_.front().barrier) return std::nullopt;
    const Tracked& cur = moves_.front();
    // On its way (or done): it should have stopped at its end; not started:
    // at its start, the end of the move before.
    const bool started = cur.progress > cur.end_tolerance.maxCoeff() || cur.end_reached;
    if (started && cur.rest_reported) return std::nullopt;
    const Eigen::Vector3d& target = started ? cur.to : cur.from;
    if (ends_within(cur, p, target)) return std::nullopt;
    std::string detail = cur.line + ": the machine came to rest " + mm_text((p - target).norm()) + " mm from " +
                         (started ? "this move's end " : "this move's start, before it began, ") + firmware_text(cur, target) + ", at " +
                         firmware_text(cur, p) + " (tolerance " +
                         (end_tolerance_mm_ ? mm_text(*end_tolerance_mm_) + " mm" : std::string("one step")) + " per axis)";
    return make_finding(kMoveEndMissed, now, detail);
}

std::vector<Finding> MotionOracle::verdict(const Tracked& m, Cycle now) const {
    std::vector<Finding> out;
    if (m.barrier || m.end_reached || m.rest_reported) return out;
    const double slack = path_tolerance_mm_ + m.end_tolerance.maxCoeff();
    std::string what;
    if (m.closest_end > 1e299) {
        what = m.line + ": the tool skipped this move (to " + firmware_text(m, m.to) + ")";
    } else if (ends_within(m, m.closest_at, m.to) && !m.free && m.progress < m.length - slack) {
        // At its end only by standing at its start: a closed path not run.
        what = m.line + ": the tool left this move after " + mm_text(m.progress) + " of its " + mm_text(m.length) + " mm";
    } else {
        what = m.line + ": the tool left this move " + mm_text(m.closest_end) + " mm from its end " + firmware_text(m, m.to) +
               " (closest at " + firmware_text(m, m.closest_at) + ")";
    }
    out.push_back(make_finding(kMoveEndMissed, now, what));
    return out;
}

void MotionOracle::finish_front(Cycle now) {
    Tracked& m = moves_.front();
    for (const Finding& f : verdict(m, now)) report(f.kind, f.detail);
    if (m.drawing()) last_drawing_ = m;
    ++moves_judged_;
    moves_.pop_front();
}

std::vector<Finding> MotionOracle::pending_findings() const {
    std::vector<Finding> out;
    if (moves_.empty()) return out;
    const Cycle now = clock().cycle();
    // The run's end is a rest once nothing moved for the rest time in force
    // (a run that ends done waited that long: Bench::still_going); a run cut
    // off while the machine moves has its moves under way, not missed.
    const Cycle settle = rest_cycles_now();
    if (now < last_move_cycle_ + settle) return out;
    const Eigen::Vector3d p = tool_position();
    if (!rest_judged_) {
        if (auto f = rest_verdict(p, now)) out.push_back(*f);
    }
    if (job_answered_ && job_answered_()) {
        if (auto f = unmade_verdict(p, now)) out.push_back(*f);
    }
    return out;
}

bool MotionOracle::frame_restored() {
    if (!lost_) return true;  // the retract of the line took its stop back
    if (moves_.empty() || !moves_.back().barrier) return false;
    moves_.pop_back();
    lost_ = false;
    lost_why_.clear();
    return true;
}

void MotionOracle::judged_elsewhere(const std::string& line) {
    for (Tracked& m : moves_) {
        if (m.line == line) m.unreachable = true;
    }
}

bool MotionOracle::still_going(std::string* why) const {
    if (lost_ || moves_.empty() || moves_.front().barrier) return false;
    const Tracked& cur = moves_.front();
    const bool begun = cur.progress > cur.end_tolerance.maxCoeff() || cur.end_reached;
    if (clock().cycle() < last_move_cycle_ + rest_cycles_now()) {
        // Moving (or within rest_time of it): on its way through the moves.
        if (cur.end_reached && moves_.size() == 1) return false;
        if (why != nullptr) {
            *why = cur.line + " under way (the tool at " + firmware_text(cur, tool_position()) + ", its end " +
                   firmware_text(cur, cur.to) + ")";
        }
        return true;
    }
    // At rest: a move begun and left short was judged there (rest_verdict);
    // one not begun may yet begin (a firmware waiting for its heater first).
    const std::size_t first = begun ? 1 : 0;
    if (first >= moves_.size() || moves_[first].barrier || moves_[first].unreachable) return false;
    if (why != nullptr) {
        const Tracked& next = moves_[first];
        *why = next.line + " accepted and not begun (the tool at rest at " + firmware_text(next, tool_position()) +
               ", the move to " + firmware_text(next, next.to) + ")";
        const auto more = std::count_if(moves_.begin() + static_cast<std::ptrdiff_t>(first) + 1, moves_.end(),
                                        [](const Tracked& m) { return !m.barrier; });
        if (more > 0) *why += ", " + std::to_string(more) + " more after it";
    }
    return true;
}

std::optional<Finding> MotionOracle::unmade_verdict(const Eigen::Vector3d& p, Cycle now) const {
    if (lost_ || moves_.empty() || moves_.front().barrier) return std::nullopt;
    const Tracked& cur = moves_.front();
    const bool begun = cur.progress > cur.end_tolerance.maxCoeff() || cur.end_reached;
    // The move the tool is on counts when it never left its start; away
    // from it, rest_verdict has judged it already.
    std::size_t first = begun || ends_within(cur, p, cur.to) || !ends_within(cur, p, cur.from) ? 1 : 0;
    // A move behind a dwell may still be waiting it out (a run ends 50 ms
    // after the last step): only the moves before the first dwell count.
    std::size_t unmade = 0;
    for (std::size_t i = first; i < moves_.size() && !moves_[i].barrier && !moves_[i].after_dwell; ++i) ++unmade;
    if (unmade == 0) return std::nullopt;
    const Tracked& m = moves_[first];
    std::string detail = m.line + ": every line was answered, and the run ended with the machine at rest at " +
                         firmware_text(m, p) + " before this move to " + firmware_text(m, m.to) + " began";
    if (unmade > 1) detail += " (nor did the " + std::to_string(unmade - 1) + " after it)";
    return make_finding(kMoveEndMissed, now, detail);
}

std::size_t MotionOracle::moves_judged_now() const {
    std::size_t judged = moves_judged_;
    if (moves_.empty() || moves_.front().barrier) return judged;
    const Tracked& cur = moves_.front();
    const Eigen::Vector3d p = tool_position();
    const Cycle now = clock().cycle();
    const bool at_rest = now >= last_move_cycle_ + rest_cycles_now();
    // The cursor's move is judged once it reached its end, or the machine
    // came to rest anywhere but at its start (a rest verdict was given).
    const bool cursor_judged =
        cur.end_reached || cur.rest_reported || (at_rest && rest_judged_ && !ends_within(cur, p, cur.from));
    if (cursor_judged) ++judged;
    // The moves a finished job left unmade are judged together (unmade_verdict).
    const Cycle settle = std::min(rest_cycles_, clock().cycles_from_seconds(0.025));
    if (!lost_ && job_answered_ && job_answered_() && now >= last_move_cycle_ + settle) {
        for (std::size_t i = cursor_judged ? 1 : 0; i < moves_.size() && !moves_[i].barrier && !moves_[i].after_dwell; ++i) {
            ++judged;
        }
    }
    return judged;
}

std::string MotionOracle::summary() {
    const std::size_t found = findings().size() + pending_findings().size();
    char line[200];
    std::snprintf(line, sizeof line, "oracle     %s: %zu moves judged, %zu findings", name().c_str(), moves_judged_now(), found);
    std::string text = line;
    if (lost_) {
        text += "; stopped judging: " + lost_why_;
    } else if (commands_ == 0 && job_answered_) {
        // Nothing to judge is not "all clean": say why the oracle saw no move.
        text += "; the job commanded no move";
    } else if (commands_ == 0) {
        text += "; nothing was commanded through the bench (no G-code job; a host on --pty, such as klippy with "
                "Klipper's binary protocol, talks to the firmware itself)";
    }
    return text;
}

}  // namespace avrbench
