// Reads the LINE, ARC and CIRCLE entities of an ASCII or binary DXF file with
// dxflib (Debian libdxflib-dev), as seed 002's CAD2G reads AutoCAD drawings:
// a line from its start to its end point; an arc counter-clockwise from its
// start angle to its end angle (DXF group codes 50/51, degrees); a circle as
// a clockwise arc starting and ending at its rightmost point (the thesis
// emits circles as G02). Other entities are counted and skipped.
#pragma once

#include <string>

#include "cam/Drawing.hpp"

namespace avrbench {

struct DxfReadResult {
    Drawing drawing;
    unsigned skipped_entities = 0;  // points, polylines, text, ...
};

// Throws BadInput "<path>: ..." for a file that cannot be read or holds no
// line, arc or circle.
DxfReadResult read_dxf(const std::string& path);

}  // namespace avrbench
