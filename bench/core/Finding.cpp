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
    }
    return "unknown";
}

std::string Finding::describe() const {
    char head[160];
    const double time_us = clock_hz ? static_cast<double>(cycle) * 1e6 / clock_hz : 0.0;
    std::snprintf(head, sizeof head, "%s: %s at cycle %llu (%.3f us), PC 0x%04x %s", mcu.c_str(),
                  to_string(kind), static_cast<unsigned long long>(cycle), time_us, pc_bytes, "");
    std::string out = head;
    out += symbol;
    if (!detail.empty()) out += ": " + detail;
    return out;
}

}  // namespace avrbench
