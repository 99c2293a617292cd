// Structure-aware mutation of G-code for fuzzing firmware (bench/fuzz): keeps
// lines mostly well formed and aims at what parsers get wrong - extreme and
// malformed numbers (1e9, -0, 99999999999), a missing F word, overlong lines,
// huge or degenerate arcs, binary bytes, plausible numbers a few times off
// (where a machine's reachable space ends) - and otherwise hands the bytes to a
// byte-level mutator (libFuzzer's LLVMFuzzerMutate). Deterministic: the
// same input, size limit and seed give the same output.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace avrbench {

enum class GcodeMutation {
    ExtremeNumber,   // a number replaced by 1e9, -0, 99999999999, ...
    DropWord,        // one word (often F) removed from a line
    InsertWord,      // a dictionary word added to a line
    NewLine,         // a dictionary line (moves, arcs, M-codes) inserted
    DuplicateLine,
    OverlongLine,    // a line padded past 50..400 bytes
    BinaryByte,      // a byte outside printable ASCII inserted
    DegenerateArc,   // G2/G3 with a zero or huge radius, or the end at the start
    NearbyNumber,    // a number moved within a few times its size: a target just outside the workspace
    ByteLevel,       // the fallback mutator's change
};

const char* to_string(GcodeMutation mutation);

// The G/M words and axis letters the mutator draws from; also written as a
// libFuzzer/AFL++ dictionary by `avrbench fuzz`.
const std::vector<std::string>& gcode_dictionary();

using ByteMutator = std::size_t (*)(std::uint8_t* data, std::size_t size, std::size_t max_size);

// Mutates data[0..size) in place (up to max_size bytes) and returns the new
// size; `byte_level` may be null (then ByteLevel is never chosen). `chosen`,
// when given, receives the mutation applied.
std::size_t mutate_gcode(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned seed,
                         ByteMutator byte_level, GcodeMutation* chosen = nullptr);

}  // namespace avrbench
