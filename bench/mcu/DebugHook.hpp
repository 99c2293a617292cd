// What a debugger sees of an MCU's run loop (debug/Debugger.hpp is the one
// that implements it). With a hook attached the run loop takes its general
// path for every step and calls before_step() in front of each, so a
// debugger can stop in front of any instruction, look and change state, and
// return to let the run go on. Everything else on the board waits meanwhile:
// simulated time does not advance while a person thinks.
#pragma once

namespace avrbench {

class Mcu;

class DebugHook {
public:
    virtual ~DebugHook() = default;
    // In front of the MCU's next step (an instruction, or a jump while it
    // sleeps); may serve a debugger before returning. May throw to abandon
    // the run (a debugger that replays from the start); nothing of simavr's
    // is on the stack then.
    virtual void before_step(Mcu& mcu) = 0;
    // The MCU halted (a crash finding); its run loop ends after this.
    virtual void halted(Mcu& mcu) = 0;
};

}  // namespace avrbench
