// The HTML report's data (RunReport) assembled from a run, through a narrow
// read-only view of it: the report reads the timeline, the MCUs and parts
// and what the serial ports carried, and changes nothing.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "trace/RunReport.hpp"

namespace avrbench {

class Mcu;
class Part;

// What a report reads of a run (run/Bench implements it).
class RunView {
public:
    virtual const Timeline& timeline() const = 0;
    virtual std::vector<Mcu*> mcus() const = 0;
    virtual std::vector<Part*> parts() const = 0;
    virtual std::string board_path() const = 0;
    virtual double now_seconds() const = 0;
    // Each serial port's lines in time order: the host's transcript, or the
    // firmware's output where no host listens.
    virtual std::vector<TranscriptLine> transcript() const = 0;
    // Temperature targets the hosts sent (M104/M109/M140/M190 S..) for the
    // parts among `plants`: (time [s], degC) each.
    virtual std::map<const Part*, std::vector<std::pair<double, double>>> temperature_targets(
        const std::vector<Part*>& plants) const = 0;
    virtual std::vector<Finding> findings() const = 0;

protected:
    ~RunView() = default;
};

// The report of `run`, titled `title` (the timeline must be traced).
RunReport make_run_report(const RunView& run, const std::string& title);

// The signals make_run_report reads (by SignalId): the parts' signals that
// declare a role (positions, temperatures, heater duty, servo angles) and
// each MCU's TWI bytes. A streamed run keeps only these in memory
// (Timeline::keep_when_taken) and still reports the same.
std::vector<bool> report_signal_mask(const RunView& run);

}  // namespace avrbench
