// Orders and orients a drawing's segments so the pen lifts as rarely as
// possible: seed 002's "align entities" algorithm (App. A1) with a distance
// tolerance where the thesis compared floats for equality, and without its
// out-of-range read. Then the emission rule: a rapid move (G00, pen up) to a
// segment's start only where the previous segment ended elsewhere.
#pragma once

#include <string>

#include "cam/Drawing.hpp"

namespace avrbench {

struct ChainStats {
    unsigned revisions = 0;  // passes of the alignment loop (at most 100)
};

// Reorders and reverses `drawing.segments` in place; points closer than
// `tolerance_mm` are the same point.
ChainStats align_segments(Drawing& drawing, double tolerance_mm);

struct GcodeProgram {
    std::string text;         // the .nc file: G21 G90, moves, M30
    unsigned commands = 0;    // G00 + G01 + G02 + G03, as the thesis counts them
    unsigned rapids = 0;      // G00
    unsigned pen_cycles = 0;  // pen-down spells (a G00 followed by drawing)
};

// The thesis' emission: for each segment, G00 to its start unless the pen is
// already there (within `tolerance_mm`), then G01 / G02 / G03 to its end at
// `feed_mm_per_min`; I, J are the centre relative to the start.
GcodeProgram emit_gcode(const Drawing& drawing, double tolerance_mm, double feed_mm_per_min);

}  // namespace avrbench
