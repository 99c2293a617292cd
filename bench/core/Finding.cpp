#include "core/Finding.hpp"

#include <algorithm>

#include <cstdio>

namespace avrbench {

const char* to_string(FindingKind kind) {
    switch (kind) {
        case FindingKind::SimavrCrash: return "simavr-crash";
        case FindingKind::InvalidOpcode: return "invalid-opcode";
        case FindingKind::PcOutsideProgram: return "pc-outside-program";
        case FindingKind::StackOverflow: return "stack-overflow";
        case FindingKind::BadInterrupt: return "bad-interrupt";
        case FindingKind::WatchdogReset: return "watchdog-reset";
        case FindingKind::JumpToReset: return "jump-to-reset";
        case FindingKind::StepHighTooShort: return "step-high-too-short";
        case FindingKind::StepLowTooShort: return "step-low-too-short";
        case FindingKind::DirSetupViolation: return "dir-setup-violation";
        case FindingKind::DirHoldViolation: return "dir-hold-violation";
        case FindingKind::StepRateTooHigh: return "step-rate-too-high";
        case FindingKind::AxisOutOfTravel: return "axis-out-of-travel";
        case FindingKind::MotorStall: return "motor-stall";
        case FindingKind::Overheat: return "overheat";
        case FindingKind::HostProtocol: return "host-protocol";
        case FindingKind::SerialFraming: return "serial-framing";
        case FindingKind::ServoPulseOutOfRange: return "servo-pulse-out-of-range";
        case FindingKind::TargetOutOfReach: return "target-out-of-reach";
        case FindingKind::NetContention: return "net-contention";
        case FindingKind::FloatingInputRead: return "floating-input-read";
    }
    return "unknown";
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

}  // namespace avrbench
