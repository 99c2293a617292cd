// Signals grouped by scope, the way both the VCD ($scope blocks) and the gtkwave
// save file (trace groups) present them, so the two always agree.
#pragma once

#include <string>
#include <vector>

#include "trace/Timeline.hpp"

namespace avrbench {

struct ScopeGroup {
    std::string scope;
    std::vector<SignalId> signals;  // registration order
};

// One group per distinct scope, in order of the scope's first signal.
std::vector<ScopeGroup> group_by_scope(const Timeline& timeline);

}  // namespace avrbench
