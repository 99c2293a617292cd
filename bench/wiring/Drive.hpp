// What one terminal puts on a net, and the level the net settles to.
//
// A net is resolved the way a logic input sees it (ATmega328P §28.2, ATmega2560
// §31.2, ATmega32 §28 "DC Characteristics"): push-pull outputs are ideal
// sources; pull resistors (the MCU's internal pull-up, board resistors) form
// a divider whose voltage is read against V_IL max = 0.3 VCC and V_IH min =
// 0.6 VCC. What the bench decides where the datasheet leaves the level
// undefined (docs/BOARDS.md, "Electrical model and its limits"):
//  - two strong drivers at different levels: contention; the net reads 0;
//  - no driver, or a divider between V_IL and V_IH: floating; reads 0.
#pragma once

#include <span>

namespace avrbench {

enum class Strength : unsigned char {
    None,    // high impedance: an input, an open contact, an open-drain output off
    Weak,    // a resistor to VCC (level 1) or GND (level 0)
    Strong,  // a push-pull output, a closed contact, a tie
};

struct Drive {
    Strength strength = Strength::None;
    bool level = false;
    double ohms = 0;  // Weak only: the resistor's value

    static Drive none() { return {}; }
    static Drive strong(bool level) { return {Strength::Strong, level, 0}; }
    static Drive weak(bool level, double ohms) { return {Strength::Weak, level, ohms}; }
    bool operator==(const Drive&) const = default;
};

enum class NetState : unsigned char {
    Driven,      // a strong driver, or pull resistors that give a valid logic level
    Floating,    // nothing drives the net, or a divider between V_IL and V_IH
    Contention,  // strong drivers at both levels
};

struct Resolution {
    NetState state = NetState::Floating;
    bool level = false;  // what an input reads: 0 unless Driven high
    double volts_fraction = 0;  // the divider's voltage / VCC (pull resistors only)
    bool operator==(const Resolution&) const = default;
};

// V_IL max and V_IH min as fractions of VCC (the three parts' DC tables,
// "VCC = 2.4 V - 5.5 V" rows for the 328P and 2560, 4.5-5.5 V for the m32).
inline constexpr double kInputLowMaxFraction = 0.3;
inline constexpr double kInputHighMinFraction = 0.6;

Resolution resolve(std::span<const Drive> drives);

}  // namespace avrbench
