#include "core/Finding.hpp"

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
    }
    return "unknown";
}

std::string Finding::describe() const {
    char head[200];
    const double time_us = clock_hz ? static_cast<double>(cycle) * 1e6 / clock_hz : 0.0;
    std::snprintf(head, sizeof head, "%s: %s at cycle %llu (%.3f us)", source.c_str(), to_string(kind),
                  static_cast<unsigned long long>(cycle), time_us);
    std::string out = head;
    if (has_pc) {
        std::snprintf(head, sizeof head, ", PC 0x%04x ", pc_bytes);
        out += head;
        out += symbol;
    }
    if (!detail.empty()) out += ": " + detail;
    return out;
}

}  // namespace avrbench
