// Seed 002's whole CAM chain as one job: a DXF drawing read, its segments
// aligned, emitted as G-code at a feed, and packed into the binary records
// the plotter firmware reads (docs/CNC.md).
#pragma once

#include <string>

#include "cam/Records.hpp"

namespace avrbench {

struct PlotJob {
    std::string gcode;       // what the records were made from
    RecordProgram records;   // one message per acknowledgement
};

// BadInput for an unreadable drawing or a feed outside (0, 100000] mm/min.
PlotJob plot_drawing(const std::string& dxf_path, double feed_mm_per_min, bool improved_records);

}  // namespace avrbench
