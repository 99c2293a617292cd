// A part that checks the moves a firmware accepted against what the machine
// can do: the bench hands it every G0/G1 target a host's line was answered
// "ok" to (in the part's frame, mm), and asks it about the ones refused. A delta robot is one; any mechanism
// with reach limits can be, without the bench knowing its type.
#pragma once

#include <string>

#include <Eigen/Dense>

namespace avrbench {

class AcceptedMoves {
public:
    virtual ~AcceptedMoves() = default;
    // Whether this part wants the targets (its configuration may say no).
    virtual bool checks_move_commands() const = 0;
    // `line` quotes the accepted line, for the finding's detail. False when
    // the machine cannot reach the target (a finding of this part's): the
    // move is judged, and a run need not wait for the machine to make it.
    virtual bool check_accepted_move(const Eigen::Vector3d& target_mm, const std::string& line) = 0;
    // A G0/G1 target the firmware refused (answered an error to): true when
    // the machine cannot reach it either, so the refusal is right and not a
    // finding of the host's (a delta's "error: unreachable").
    virtual bool refusal_is_right(const Eigen::Vector3d& target_mm) const = 0;
};

}  // namespace avrbench
