// Writes a Timeline as a Value Change Dump (IEEE 1364-2005 §18) for gtkwave and
// other waveform viewers.
//
// What the output promises:
// - Byte-identical for identical timelines: no $date, no wall clock, no paths.
// - Timestamps are exact cycle times when every clock has an exact VCD unit
//   (see VcdTimescale); VcdResult::exact says whether they are.
// - Events of all clock domains are merged in time order; events at the same
//   time keep the order they were recorded in.
// - At one timestamp the LAST recorded value of a signal wins (VCD describes the
//   value a signal has at a time; a zero-width glitch could not be seen anyway),
//   and an event that leaves a signal's value unchanged is dropped, so recorders
//   may record blindly.
// - $dumpvars at #0 gives each signal's value at time 0: its last event at
//   time 0, else x for wires, z for buses (nothing on the bus yet: a byte
//   stream before its first byte; viewers draw it as a neutral line, not as
//   an error) and r0 for reals (VCD has no unknown real; record a value at
//   cycle 0 when 0 would mislead).
// - Wires and 1-bit buses are written as scalars (`1!`), wider buses as one
//   scalar per bit (VcdBuses::Bits, the default) or full-width binary
//   (`b00100000 "`), reals in the shortest form that reads back to the same
//   double (`r25.5 #`, std::to_chars; also `rinf`, `rnan`).
// - Signals are listed one $scope module per distinct SignalInfo::scope, scopes
//   in order of first appearance, signals in registration order.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "trace/Timeline.hpp"

namespace avrbench {

// How buses wider than one bit are written.
enum class VcdBuses {
    // One 1-bit wire per bit, `name[msb]` .. `name[0]`: every tool reads it
    // (sigrok/PulseView's VCD input, libsigrok 0.5, takes 1-bit signals only
    // and stops at the first vector value); the .gtkw file joins the bits
    // back into one trace (GtkwOptions::buses).
    Bits,
    // One vector variable per bus (`b00100000 "`): gtkwave, surfer, Python's vcdvcd.
    Vector,
};

struct VcdOptions {
    VcdBuses buses = VcdBuses::Bits;
    // Aliases (a net's or label's name for a pin) get identifier codes of
    // their own and repeat the target's changes: readers that keep one
    // signal per code (libsigrok 0.5 leaves every later one empty) show them.
    // false: they share the target's code (smaller; gtkwave reads both).
    bool alias_codes = true;
    // When set, the dump ends with #<time of end_cycle> so viewers show the whole
    // run, not just up to the last change. Ignored when earlier than the last change.
    std::optional<Cycle> end_cycle;
    std::uint32_t end_clock_hz = 16000000;  // clock domain of end_cycle
};

struct VcdResult {
    std::string timescale;            // e.g. "100ps"
    bool exact = true;                // false: a clock has no exact VCD unit; times rounded to 1fs
    std::uint64_t value_changes = 0;  // changes written after #0 (after dedupe)
    std::uint64_t end_time = 0;       // last timestamp written, in timescale units
};

// Throws std::runtime_error naming `path` when it cannot be written,
// std::out_of_range for an event whose signal id was never registered, and
// std::overflow_error when a time does not fit 64 bits.
VcdResult write_vcd(const Timeline& timeline, const std::string& path, const VcdOptions& options = {});

// The same dump as a string (tests, small traces).
std::string format_vcd(const Timeline& timeline, const VcdOptions& options = {}, VcdResult* result = nullptr);

// A dump written while the run goes, so a long run's memory does not grow
// with its length: every few milliseconds of simulated time the caller hands
// over what the timeline recorded (Timeline::take_events) up to a time no
// later event can precede; the dump is the same bytes write_vcd would write
// for the whole timeline at the end. Signals and aliases must all be
// registered before the first drain (the header lists them).
class VcdStream {
public:
    // Checks `path` and opens its temporary file (core/OutputFile). `layout`
    // gives buses and alias_codes (finish's options give only the end).
    VcdStream(const Timeline& timeline, const std::string& path, const VcdOptions& layout = {});
    ~VcdStream();
    VcdStream(const VcdStream&) = delete;
    VcdStream& operator=(const VcdStream&) = delete;

    // Takes the timeline's buffered events and writes those at or before
    // `settled_ps`; later ones wait for the next drain. Throws std::logic_error
    // if an event arrives for a time already written.
    void drain(Timeline& timeline, Picoseconds settled_ps);
    // Writes everything left, the end marker, and renames the file into place.
    VcdResult finish(Timeline& timeline, const VcdOptions& options);
    // Events held back (recorded, not yet written), for tests and benchmarks.
    std::size_t held_events() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The VCD identifier code number `index` (codes are handed out in signal
// order, one per bit of a bus written as bits): bijective base 94 over
// the printable characters '!'..'~', least significant digit first, so ids
// 0..93 get one character and the next 94^2 = 8836 get two.
std::string vcd_identifier(std::uint32_t index);

}  // namespace avrbench
