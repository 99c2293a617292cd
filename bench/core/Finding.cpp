#include "core/Finding.hpp"

#include <algorithm>
#include <deque>
#include <stdexcept>

#include <cstdio>

namespace avrbench {

const char* to_string(Severity severity) { return severity == Severity::Error ? "error" : "warning"; }

namespace {

// Declared kinds, in declaration order; a deque never moves its elements,
// so a FindingKind's pointer stays valid. Function-local: declarations run
// during static initialisation, in any order of translation units.
std::deque<FindingKind::Info>& declared_kinds() {
    static std::deque<FindingKind::Info> kinds;
    return kinds;
}

const FindingKind::Info kUnspecified{"unspecified", "a finding whose kind was never set", Severity::Warning};

}  // namespace

FindingKind::FindingKind() : info_(&kUnspecified) {}

FindingKind FindingKind::declare(std::string name, std::string meaning, Severity severity) {
    for (const Info& info : declared_kinds()) {
        if (info.name != name) continue;
        if (info.severity != severity) throw std::logic_error("finding kind '" + name + "' declared with two severities");
        return FindingKind(&info);
    }
    declared_kinds().push_back({std::move(name), std::move(meaning), severity});
    return FindingKind(&declared_kinds().back());
}

std::optional<FindingKind> FindingKind::find(std::string_view name) {
    for (const Info& info : declared_kinds()) {
        if (info.name == name) return FindingKind(&info);
    }
    return std::nullopt;
}

std::vector<FindingKind> FindingKind::all() {
    std::vector<FindingKind> out;
    for (const Info& info : declared_kinds()) out.push_back(FindingKind(&info));
    std::sort(out.begin(), out.end(), [](FindingKind a, FindingKind b) { return a.name() < b.name(); });
    return out;
}

std::string Finding::describe() const {
    char head[200];
    std::string out = source + ": " + to_string(kind);
    if (clock_hz != 0) {
        std::snprintf(head, sizeof head, " at %.6f s (cycle %llu)", static_cast<double>(cycle) / clock_hz,
                      static_cast<unsigned long long>(cycle));
    } else {
        std::snprintf(head, sizeof head, " at cycle %llu", static_cast<unsigned long long>(cycle));
    }
    out += head;
    if (has_pc) {
        std::snprintf(head, sizeof head, ", PC 0x%04x ", pc_bytes);
        out += head;
        out += symbol;
    }
    if (!detail.empty()) out += ": " + detail;
    return out;
}

std::vector<std::string> summarize_findings(const std::vector<Finding>& findings, std::size_t first_n) {
    std::vector<std::string> lines;
    for (std::size_t i = 0; i < findings.size() && i < first_n; ++i) lines.push_back(findings[i].describe());
    if (findings.size() <= first_n) return lines;
    // The rest as a count per (kind, source), in order of first appearance.
    std::vector<std::pair<std::string, std::size_t>> counts;
    for (std::size_t i = first_n; i < findings.size(); ++i) {
        const std::string key = std::string(to_string(findings[i].kind)) + " (" + findings[i].source + ")";
        auto it = std::find_if(counts.begin(), counts.end(), [&](const auto& c) { return c.first == key; });
        if (it == counts.end()) counts.emplace_back(key, 1);
        else ++it->second;
    }
    std::string more = "... and " + std::to_string(findings.size() - first_n) + " more:";
    for (std::size_t i = 0; i < counts.size(); ++i) {
        more += (i == 0 ? " " : ", ") + counts[i].first + " x" + std::to_string(counts[i].second);
    }
    lines.push_back(more);
    return lines;
}

namespace {
thread_local std::uint64_t recorded_findings = 0;
}  // namespace

std::uint64_t findings_recorded() { return recorded_findings; }
void finding_log_detail::count_recorded() { ++recorded_findings; }

}  // namespace avrbench
