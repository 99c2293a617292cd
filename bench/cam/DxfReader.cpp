#include "cam/DxfReader.hpp"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <dl_creationadapter.h>
#include <dl_dxf.h>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"

namespace avrbench {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

class Collector final : public DL_CreationAdapter {
public:
    DxfReadResult result;

    void addLine(const DL_LineData& d) override {
        Segment s;
        s.kind = Segment::Kind::Line;
        s.start = {d.x1, d.y1};
        s.end = {d.x2, d.y2};
        result.drawing.segments.push_back(s);
    }
    void addArc(const DL_ArcData& d) override {
        Segment s;
        s.kind = Segment::Kind::ArcCcw;
        s.centre = {d.cx, d.cy};
        s.start = {d.cx + d.radius * std::cos(d.angle1 * kDegToRad), d.cy + d.radius * std::sin(d.angle1 * kDegToRad)};
        s.end = {d.cx + d.radius * std::cos(d.angle2 * kDegToRad), d.cy + d.radius * std::sin(d.angle2 * kDegToRad)};
        result.drawing.segments.push_back(s);
    }
    void addCircle(const DL_CircleData& d) override {
        Segment s;
        s.kind = Segment::Kind::ArcCw;
        s.centre = {d.cx, d.cy};
        s.start = s.end = {d.cx + d.radius, d.cy};
        result.drawing.segments.push_back(s);
    }
    void addPoint(const DL_PointData&) override { ++result.skipped_entities; }
    void addPolyline(const DL_PolylineData&) override { ++result.skipped_entities; }
    void addText(const DL_TextData&) override { ++result.skipped_entities; }
    void addMText(const DL_MTextData&) override { ++result.skipped_entities; }
    void addEllipse(const DL_EllipseData&) override { ++result.skipped_entities; }
    void addSpline(const DL_SplineData&) override { ++result.skipped_entities; }
};

}  // namespace

DxfReadResult read_dxf(const std::string& path) {
    // Read by the bench (a regular file, bounded) and handed to dxflib as a stream.
    std::istringstream stream(read_input_file(path, "DXF drawing", kMaxDxfFileBytes));
    Collector collector;
    DL_Dxf dxf;
    if (!dxf.in(stream, &collector)) throw BadInput(escaped(path) + ": cannot be read as DXF");
    collector.result.drawing.source = path;
    for (const auto& s : collector.result.drawing.segments) {
        for (double v : {s.start.x, s.start.y, s.end.x, s.end.y, s.centre.x, s.centre.y}) {
            if (!std::isfinite(v)) throw BadInput(path + ": an entity has a coordinate that is not a number");
        }
    }
    if (collector.result.drawing.segments.empty()) {
        throw BadInput(path + ": no LINE, ARC or CIRCLE entity (a pen plotter draws only those)");
    }
    return collector.result;
}

}  // namespace avrbench
