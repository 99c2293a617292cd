#include "cam/Chain.hpp"

#include <cstdio>
#include <utility>

namespace avrbench {

ChainStats align_segments(Drawing& drawing, double tolerance_mm) {
    auto& e = drawing.segments;
    const std::size_t n = e.size();
    auto same = [tolerance_mm](const Point2& a, const Point2& b) { return distance(a, b) <= tolerance_mm; };
    ChainStats stats;
    bool changed = true;
    while (changed && stats.revisions < 100) {
        changed = false;
        for (std::size_t j = 0; j < n; ++j) {
            for (std::size_t k = j + 1; k < n; ++k) {
                if (same(e[k].end, e[j].end)) {
                    // Case 1: k ends where j ends: draw k the other way.
                    e[k] = e[k].reversed();
                    changed = true;
                } else if (same(e[k].start, e[j].start)) {
                    // Case 2: both start at one point: reverse k, and it goes first.
                    e[k] = e[k].reversed();
                    std::swap(e[j], e[k]);
                    changed = true;
                } else if (same(e[j].start, e[k].end)) {
                    // Case 3: k ends where j starts: k goes first.
                    std::swap(e[j], e[k]);
                    changed = true;
                }
            }
        }
        if (!changed) break;
        // Re-chain: after each segment, the one that starts where it ends.
        for (std::size_t j = 0; j + 1 < n; ++j) {
            if (same(e[j + 1].start, e[j].end)) continue;
            for (std::size_t k = j + 2; k < n; ++k) {
                if (same(e[k].start, e[j].end)) {
                    std::swap(e[j + 1], e[k]);
                    break;
                }
            }
        }
        ++stats.revisions;
    }
    return stats;
}

GcodeProgram emit_gcode(const Drawing& drawing, double tolerance_mm, double feed_mm_per_min) {
    GcodeProgram p;
    char line[160];
    p.text = "G21 G90\n";
    const Point2* pen_at = nullptr;
    for (const auto& s : drawing.segments) {
        if (pen_at == nullptr || distance(*pen_at, s.start) > tolerance_mm) {
            std::snprintf(line, sizeof line, "G00 X%.3f Y%.3f\n", s.start.x, s.start.y);
            p.text += line;
            ++p.commands;
            ++p.rapids;
            ++p.pen_cycles;
        }
        if (s.kind == Segment::Kind::Line) {
            std::snprintf(line, sizeof line, "G01 X%.3f Y%.3f F%.0f\n", s.end.x, s.end.y, feed_mm_per_min);
        } else {
            std::snprintf(line, sizeof line, "%s X%.3f Y%.3f I%.3f J%.3f F%.0f\n", s.gcode(), s.end.x, s.end.y,
                          s.centre.x - s.start.x, s.centre.y - s.start.y, feed_mm_per_min);
        }
        p.text += line;
        ++p.commands;
        pen_at = &s.end;
    }
    p.text += "M30\n";
    return p;
}

}  // namespace avrbench
