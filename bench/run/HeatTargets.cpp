#include "run/HeatTargets.hpp"

#include "core/GcodeLexer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "boards/Board.hpp"
#include "parts/Part.hpp"
#include "run/Bench.hpp"

namespace avrbench {

std::vector<Part*> heated_parts(const Board& board) {
    std::vector<Part*> out;
    for (Part* p : board.parts()) {
        for (const PartSignalInfo& info : p->signals()) {
            if (info.role == "temperature") {
                out.push_back(p);
                break;
            }
        }
    }
    return out;
}

Part* heated_part_for(const std::vector<Part*>& heated, const std::string& gcode_line, double* target_degC) {
    const auto words = gcode_words(gcode_line);
    const auto m = words.find('M'), s = words.find('S');
    if (m == words.end() || s == words.end()) return nullptr;
    Part* bed = nullptr;
    std::vector<Part*> tools;
    for (Part* p : heated) {
        if (p->name().find("bed") != std::string::npos) {
            if (bed == nullptr) bed = p;
        } else {
            tools.push_back(p);
        }
    }
    Part* part = nullptr;
    if (m->second == 140 || m->second == 190) {
        part = bed;
    } else if (m->second == 104 || m->second == 109) {
        const auto tool = words.find('T');
        const std::size_t index = tool == words.end() || tool->second < 0 ? 0 : static_cast<std::size_t>(tool->second);
        part = index < tools.size() ? tools[index] : nullptr;
    }
    if (part != nullptr && target_degC != nullptr) *target_degC = s->second;
    return part;
}

HeatTargets::HeatTargets(const Board& board) : heated_(heated_parts(board)) {}

void HeatTargets::accepted(const std::string& line, Picoseconds now_ps, const std::string& quoted) {
    double degC = 0;
    Part* part = heated_part_for(heated_, line, &degC);
    if (part == nullptr) return;
    if (degC <= 0) {
        targets_.erase(part);  // off: nothing to reach
        return;
    }
    targets_[part] = Target{degC, now_ps, quoted};
}

double HeatTargets::temperature_degC(const Part& part) const {
    // What the firmware regulates on: its sensor's temperature where the part
    // has one, else the body's.
    std::optional<double> body;
    for (std::size_t i = 0; i < part.signals().size(); ++i) {
        const std::string& role = part.signals()[i].role;
        if (role == "sensor-temperature") return part.signal_value(i);
        if (role == "temperature" && !body) body = part.signal_value(i);
    }
    return body.value_or(0.0);
}

void HeatTargets::sample(Picoseconds now_ps) {
    constexpr Picoseconds kEvery_ps = kPsPerMs * 250;
    const auto window_ps = static_cast<Picoseconds>(kQuietWindow_s * 1e12);
    for (const auto& [part, target] : targets_) {
        auto& h = history_[part];
        if (!h.empty() && now_ps < h.back().first + kEvery_ps) continue;
        h.emplace_back(now_ps, temperature_degC(*part));
        while (h.size() > 2 && h[1].first + window_ps <= now_ps) h.pop_front();
    }
}

bool HeatTargets::unsettled(Picoseconds now_ps, std::vector<std::string>* why) const {
    bool any = false;
    const auto window_ps = static_cast<Picoseconds>(kQuietWindow_s * 1e12);
    for (const auto& [part, target] : targets_) {
        const double t = temperature_degC(*part);
        if (std::abs(t - target.degC) <= kBand_degC) continue;
        // No longer changing: samples cover the whole window since the target
        // was set, and they span less than kQuiet_degC.
        const auto h = history_.find(part);
        if (h != history_.end() && !h->second.empty() && now_ps >= target.since_ps + window_ps &&
            h->second.front().first + window_ps <= now_ps + kPsPerMs * 250) {
            const auto [low, high] = std::minmax_element(h->second.begin(), h->second.end(),
                                                         [](const auto& a, const auto& b) { return a.second < b.second; });
            if (high->second - low->second < kQuiet_degC) continue;
        }
        any = true;
        if (why == nullptr) return true;
        char text[96];
        std::snprintf(text, sizeof text, " at %.1f degC, heading for %.0f degC (", t, target.degC);
        why->push_back(part->name() + text + target.line + ")");
    }
    return any;
}

}  // namespace avrbench
