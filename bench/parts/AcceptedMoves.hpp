// A part that checks the moves a firmware accepted against what the machine
// can do: the bench hands it every G0/G1 target a host's line was answered
// "ok" to (in the part's frame, mm). A delta robot is one; any mechanism
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
    // `line` quotes the accepted line, for the finding's detail.
    virtual void check_accepted_move(const Eigen::Vector3d& target_mm, const std::string& line) = 0;
};

}  // namespace avrbench
