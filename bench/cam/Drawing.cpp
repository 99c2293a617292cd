#include "cam/Drawing.hpp"

#include <cmath>
#include <utility>

namespace avrbench {

double distance(const Point2& a, const Point2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

Segment Segment::reversed() const {
    Segment r = *this;
    std::swap(r.start, r.end);
    if (kind == Kind::ArcCcw) r.kind = Kind::ArcCw;
    else if (kind == Kind::ArcCw) r.kind = Kind::ArcCcw;
    return r;
}

const char* Segment::gcode() const {
    switch (kind) {
        case Kind::Line: return "G01";
        case Kind::ArcCcw: return "G03";
        case Kind::ArcCw: return "G02";
    }
    return "G01";
}

}  // namespace avrbench
