// A timer's compare output (OCnx) that repeats the same waveform every
// period, handed to its consumers as one description instead of an event per
// edge. Teacup keeps a RAMPS bed at duty 0 in 8-bit fast PWM at clk/1: the
// datasheet's "narrow spike for each MAX+1 timer clock" (ATmega2560 §17.9.3)
// is 125 000 edges per simulated second, each a timer event, a net update and
// a step of the thermal model, while nothing about it changes.
//
// The timer model (periph/timer/TimerModel) hands a pin's waveform out only
// when all of this holds, and otherwise drives the pin edge by edge:
//  - the timer is idle in the sense of its quiescence check: every flag one
//    period sets is already set with its interrupt disabled, no OCRnx update
//    is buffered, the prescaler is clk_I/O / 2^k;
//  - one period, run on a copy of the counter, ends in the state it began;
//  - the pin is an output (DDxn = 1), driven by this comparator alone, with
//    no pin change interrupt enabled on it;
//  - the only listeners on the pin's simavr IRQ are simavr's port module and
//    the sink's own (a traced pin, an INTn, ICPn or Tn input refuses);
//  - a sink was registered for the pin (PeriodicOutputSink) and accepts.
// The waveform ends, at a whole-period boundary, before anything can observe
// the difference: a write to the timer's registers or to the pin's port,
// a read of TCNTn or PINx, a flag cleared, a reset. The pin's level at a
// period boundary is the level it had when the wave began, so the pin's IRQ,
// PINx and the net hold the right value at both ends; in between they hold
// the start level, which only the sink's consumers could read.
#pragma once

#include <array>
#include <cstddef>

#include "core/Time.hpp"

namespace avrbench {

struct PeriodicWave {
    struct Edge {
        Cycle offset = 0;  // cycles after the period's start, 0 < offset <= period
        bool level = false;
    };
    static constexpr std::size_t kMaxEdges = 4;

    Cycle start = 0;          // a period boundary, where the pin is at start_level
    Cycle period = 1;         // in cycles of the MCU's clock
    bool start_level = false;
    std::size_t edge_count = 0;
    std::array<Edge, kMaxEdges> edges{};  // in order of offset

    // Level at cycle `c` >= start (an edge at cycle e shows from e on).
    bool level_at(Cycle c) const;
    // Cycles the pin is high in [start, c).
    Cycle high_cycles_until(Cycle c) const;
    Cycle high_cycles_per_period() const;
};

class PeriodicOutputSink {
public:
    virtual ~PeriodicOutputSink() = default;
    // The pin follows `wave` from wave.start on; false refuses (the timer
    // then drives the pin edge by edge).
    virtual bool begin_wave(const PeriodicWave& wave) = 0;
    // The wave ended at period boundary `at`; the pin is at wave.start_level
    // there and is driven edge by edge from then on.
    virtual void end_wave(Cycle at) = 0;
    // The simavr IRQ listener this sink stands for (a Pin's), accepted on the
    // pin besides simavr's port module; nullptr for none.
    virtual const void* listener_param() const = 0;
};

}  // namespace avrbench
