// A finding: something the firmware did that a bench engineer must look at
// (a crash, a reset, a driver timing violation, an axis crash). Reported with
// the cycle, and for the MCU's own findings the PC and nearest ELF symbol so
// it can be found in the listing.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/Time.hpp"

namespace avrbench {

enum class FindingKind {
    SimavrCrash,       // simavr stopped the core (e.g. write outside RAM)
    InvalidOpcode,     // an opcode the AVR core does not decode
    PcOutsideProgram,  // PC left the loaded program (erased flash or past flashend)
    StackOverflow,     // SP went below the end of .data/.bss/.noinit
    BadInterrupt,      // an enabled interrupt without a handler reached __bad_interrupt
    WatchdogReset,     // the watchdog timed out in system-reset mode
    JumpToReset,       // execution reached the reset vector without a hardware reset

    // Found by parts watching the firmware's pins (parts/).
    StepHighTooShort,    // STEP active shorter than the driver's minimum
    StepLowTooShort,     // STEP inactive shorter than the driver's minimum
    DirSetupViolation,   // DIR changed too shortly before an active STEP edge
    DirHoldViolation,    // DIR changed too shortly after an active STEP edge
    StepRateTooHigh,     // STEP period shorter than the driver's maximum rate allows
    AxisOutOfTravel,     // an axis was driven past either end of its travel (a crash)
    MotorStall,          // a stepper motor's rotor lost synchronism with its excitation (lost steps)
    Overheat,            // a thermal plant passed its safe maximum temperature
    HostProtocol,        // the UART host saw error / ALARM / !! or got no answer
    SerialFraming,       // a pin-level serial frame with a bad stop bit or edges off the bit grid
    ServoPulseOutOfRange,  // an RC servo pulse wider or narrower than its calibrated range
    TargetOutOfReach,    // the firmware answered ok to a move the machine cannot make (a delta's arms or servos)

    // Found by the nets (wiring/).
    NetContention,       // two outputs drive one net to opposite levels
    FloatingInputRead,   // the firmware read an input pin whose net nothing drives
    kLast = FloatingInputRead,
};

const char* to_string(FindingKind kind);

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

}  // namespace avrbench
