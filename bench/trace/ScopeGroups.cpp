#include "trace/ScopeGroups.hpp"

#include <map>

namespace avrbench {

std::vector<ScopeGroup> group_by_scope(const Timeline& timeline) {
    std::vector<ScopeGroup> groups;
    std::map<std::string, std::size_t> group_of;  // keeps this linear-ish for thousands of scopes
    const auto& infos = timeline.signals();
    for (std::size_t id = 0; id < infos.size(); ++id) {
        const auto [it, inserted] = group_of.emplace(infos[id].scope, groups.size());
        if (inserted) groups.push_back(ScopeGroup{infos[id].scope, {}});
        groups[it->second].signals.push_back(static_cast<SignalId>(id));
    }
    return groups;
}

}  // namespace avrbench
