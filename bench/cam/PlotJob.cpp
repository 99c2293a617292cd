#include "cam/PlotJob.hpp"

#include "cam/Chain.hpp"
#include "cam/DxfReader.hpp"
#include "core/Errors.hpp"

namespace avrbench {

namespace {
// Segments closer than this are one point (the CAM's alignment and arc fit).
constexpr double kToleranceMm = 0.01;
}  // namespace

PlotJob plot_drawing(const std::string& dxf_path, double feed_mm_per_min, bool improved_records) {
    if (!(feed_mm_per_min > 0 && feed_mm_per_min <= 1e5)) throw BadInput("--feed: mm/min above 0 and at most 100000");
    Drawing drawing = read_dxf(dxf_path).drawing;
    align_segments(drawing, kToleranceMm);
    PlotJob job;
    job.gcode = emit_gcode(drawing, kToleranceMm, feed_mm_per_min).text;
    RecordOptions options;
    options.improved = improved_records;
    job.records = records_from_gcode(job.gcode, options, dxf_path);
    return job;
}

}  // namespace avrbench
