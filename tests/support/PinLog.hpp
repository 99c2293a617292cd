// The one pin-edge logger of the tests: every level change of one MCU pin
// from the moment the log is made, with the cycle the bench stamps it with.
// Taken from the MCU pin itself, so it is independent of any part model.
#pragma once

#include <string>
#include <vector>

#include "mcu/Mcu.hpp"

namespace avrbench::test {

class PinLog {
public:
    struct Edge {
        Cycle cycle;
        bool level;
    };

    PinLog(Mcu& mcu, const std::string& pin) : initial_(mcu.pin(pin).level()) {
        mcu.pin(pin).on_change([this](Cycle cycle, bool level) {
            edges_.push_back({cycle, level});
            (level ? rises_ : falls_).push_back(cycle);
        });
    }
    PinLog(const PinLog&) = delete;
    PinLog& operator=(const PinLog&) = delete;

    bool initial() const { return initial_; }
    const std::vector<Edge>& edges() const { return edges_; }
    std::vector<Cycle> cycles() const {
        std::vector<Cycle> out;
        for (const auto& e : edges_) out.push_back(e.cycle);
        return out;
    }
    // The level the pin had at `cycle` (an edge at `cycle` counts).
    bool level_at(Cycle cycle) const {
        bool level = initial_;
        for (const auto& e : edges_) {
            if (e.cycle > cycle) break;
            level = e.level;
        }
        return level;
    }
    const std::vector<Cycle>& rises() const { return rises_; }
    const std::vector<Cycle>& falls() const { return falls_; }
    // Cycles between consecutive edges (any direction).
    std::vector<Cycle> intervals() const { return differences(cycles()); }
    // For every rising edge followed by a falling one: how long the pin was high.
    std::vector<Cycle> high_times() const { return widths(true); }
    std::vector<Cycle> low_times() const { return widths(false); }
    // Cycles the pin spent high from the log's start until `end`.
    Cycle high_cycles_until(Cycle end) const {
        Cycle total = 0;
        for (std::size_t i = 0; i < edges_.size(); ++i) {
            if (!edges_[i].level) continue;
            const Cycle off = i + 1 < edges_.size() ? std::min(edges_[i + 1].cycle, end) : end;
            if (edges_[i].cycle < off) total += off - edges_[i].cycle;
        }
        return total;
    }

    static std::vector<Cycle> differences(const std::vector<Cycle>& v) {
        std::vector<Cycle> out;
        for (std::size_t i = 1; i < v.size(); ++i) out.push_back(v[i] - v[i - 1]);
        return out;
    }

private:
    std::vector<Cycle> widths(bool level) const {
        std::vector<Cycle> out;
        for (std::size_t i = 1; i < edges_.size(); ++i) {
            if (edges_[i - 1].level == level && edges_[i].level != level) out.push_back(edges_[i].cycle - edges_[i - 1].cycle);
        }
        return out;
    }

    bool initial_;
    std::vector<Edge> edges_;
    std::vector<Cycle> rises_, falls_;
};

}  // namespace avrbench::test
