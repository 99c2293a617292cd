#include "wiring/Drive.hpp"

namespace avrbench {

Resolution resolve(std::span<const Drive> drives) {
    bool strong_high = false, strong_low = false;
    double conductance_up = 0, conductance_total = 0;  // siemens
    for (const Drive& d : drives) {
        if (d.strength == Strength::Strong) {
            (d.level ? strong_high : strong_low) = true;
        } else if (d.strength == Strength::Weak && d.ohms > 0) {
            conductance_total += 1.0 / d.ohms;
            if (d.level) conductance_up += 1.0 / d.ohms;
        }
    }
    if (strong_high && strong_low) return {NetState::Contention, false, 0};
    if (strong_high || strong_low) return {NetState::Driven, strong_high, strong_high ? 1.0 : 0.0};
    if (conductance_total <= 0) return {NetState::Floating, false, 0};
    const double fraction = conductance_up / conductance_total;
    if (fraction >= kInputHighMinFraction) return {NetState::Driven, true, fraction};
    if (fraction <= kInputLowMaxFraction) return {NetState::Driven, false, fraction};
    return {NetState::Floating, false, fraction};
}

}  // namespace avrbench
