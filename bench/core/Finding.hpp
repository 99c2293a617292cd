// A finding: something the firmware did that a bench engineer must look at
// (a crash, a reset, a driver timing violation, an axis crash). Reported with
// the cycle, and for the MCU's own findings the PC and nearest ELF symbol so
// it can be found in the listing.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/Time.hpp"

namespace avrbench {

// How much a finding weighs in a run's verdict (docs/CLI.md "exit codes").
enum class Severity : std::uint8_t {
    Warning,  // a part, a net or a host saw something wrong: fails a run under --strict
    Error,    // the firmware itself failed (crash, reset): fails every run
};
const char* to_string(Severity severity);

// What kind of finding. The set is open: whoever detects a kind declares it
// once, in its own source file (the MCU's oracles in core, nets in wiring, a
// part in its .cpp, a host in stimulus), so no lower layer lists the parts'
// kinds. Two kinds are equal when they are the same declaration.
class FindingKind {
public:
    struct Info {
        std::string name;     // "step-high-too-short": what reports, scenarios and --expect use
        std::string meaning;  // one line for people ("STEP active shorter than the driver's minimum")
        Severity severity;
    };
    // Declares a kind (a namespace-scope constant of the declarer). Declaring
    // a name twice with the same severity gives the same kind; a different
    // severity for a known name is a programming error (std::logic_error).
    static FindingKind declare(std::string name, std::string meaning, Severity severity);
    // A declared kind by name, for scenario files and command lines.
    static std::optional<FindingKind> find(std::string_view name);
    // Every declared kind, sorted by name (for messages and `avrbench findings`).
    static std::vector<FindingKind> all();

    // A kind nobody declared ("unspecified"): only a default-constructed Finding has it.
    FindingKind();
    const std::string& name() const { return info_->name; }
    const std::string& meaning() const { return info_->meaning; }
    Severity severity() const { return info_->severity; }
    friend bool operator==(FindingKind a, FindingKind b) { return a.info_ == b.info_; }

private:
    explicit FindingKind(const Info* info) : info_(info) {}
    const Info* info_;
};

inline const char* to_string(FindingKind kind) { return kind.name().c_str(); }

struct Finding {
    FindingKind kind;
    std::string source;   // which MCU or part of the board reported it
    Cycle cycle = 0;      // that MCU's cycle counter when it was detected
    std::uint32_t clock_hz = 0;
    bool has_pc = true;   // false for part findings: no PC is meaningful there
    std::uint32_t pc_bytes = 0;
    std::string symbol;   // nearest ELF symbol to the PC, "func+0x12"
    std::string detail;   // one line of explanation

    // "mcu: stack-overflow at cycle 1234 (77.125 us), PC 0x01a4 recurse+0x6: SP 0x0213 below __bss_end 0x0300"
    std::string describe() const;
};

// For people: the first `first_n` findings described in full, then one line
// counting the rest per kind and source ("... and 4990 more:
// step-high-too-short (x_driver) x4990"), so a flood stays readable.
std::vector<std::string> summarize_findings(const std::vector<Finding>& findings, std::size_t first_n = 10);

// Findings recorded so far by this thread, whoever recorded them (an MCU, a
// net, a part, a host): a debugger's --break-at-finding compares it after
// every instruction instead of asking each of them.
std::uint64_t findings_recorded();

namespace finding_log_detail {
void count_recorded();
}  // namespace finding_log_detail

// Where an owner (an MCU, a net, a part, a host) keeps what it records:
// each counted once, as it is recorded (findings_recorded). The only way a
// finding is counted.
template <typename T>
class FindingLog {
public:
    // Returns its index, for revise().
    std::size_t record(T item) {
        items_.push_back(std::move(item));
        finding_log_detail::count_recorded();
        return items_.size() - 1;
    }
    // A finding told when its fault began, its text rewritten as it grows.
    T& revise(std::size_t index) { return items_.at(index); }
    const std::vector<T>& all() const { return items_; }
    const T& back() const { return items_.back(); }
    std::size_t size() const { return items_.size(); }
    bool empty() const { return items_.empty(); }

private:
    std::vector<T> items_;
};

}  // namespace avrbench
