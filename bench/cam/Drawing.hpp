// A 2-D drawing as a pen plotter sees it: lines and circular arcs in machine
// millimetres (seed 002: the CAD layer is drawn 1:1 over the machine's work
// area, origin at home). An arc runs counter-clockwise (G03) or clockwise
// (G02) about its centre from start to end; a full circle has start == end.
#pragma once

#include <string>
#include <vector>

namespace avrbench {

struct Point2 {
    double x = 0, y = 0;
};

double distance(const Point2& a, const Point2& b);

struct Segment {
    enum class Kind { Line, ArcCcw, ArcCw };
    Kind kind = Kind::Line;
    Point2 start, end;
    Point2 centre;  // arcs only
    // The same path drawn the other way round (a CCW arc becomes a CW one).
    Segment reversed() const;
    // The G-code word that draws it: "G01", "G03", "G02".
    const char* gcode() const;
};

struct Drawing {
    std::string source;  // the file it came from
    std::vector<Segment> segments;
};

}  // namespace avrbench
