// Writes one run's RunReport as a single self-contained HTML5 file: inline CSS
// and inline SVG plots, no JavaScript, no fonts, images or anything else
// fetched (a Content-Security-Policy of default-src 'none' makes a browser
// refuse any request the file might make). Opens from a CI artifact in any
// browser, offline.
//
// What the output promises:
// - Byte-identical for identical input: no dates, no paths but those in the
//   report, numbers printed with fixed precision in the "C" locale.
// - All text from the report (title, facts, signal names, findings, UART
//   lines) is HTML-escaped; control characters and invalid UTF-8 bytes in it
//   are shown as \xNN.
// - Sections, in this order, each a <section> with a stable id:
//     header      <h1>, <ul id="facts">, badges (findings, comparison verdict)
//     findings    <table id="findings"> (rows class "finding"), or "none"
//     comparison  only when RunReport::comparison is set: <p id="comparison-summary">,
//                 <table id="comparison-channels">, and for the channel of the
//                 first divergence <svg id="comparison-<signal>"> (golden and
//                 actual overlaid, zoomed around the divergence, marked with
//                 <line class="divergence">) and <svg id="comparison-<signal>-overview">
//                 (the whole run, the zoom window shaded), and when the shift is
//                 small against that window a close-up <svg id="comparison-<signal>-detail">
//                 (six times the distance to the nearest other edge); every other channel
//                 whose verdict is not "ok" (at most kMaxComparisonPlots in all)
//                 gets a whole-run <svg id="comparison-<signal>">
//     toolpath    with >= 2 linear axes: <svg id="toolpath"> (first two linear axes,
//                 "XY"); with >= 3 also id="toolpath-xz" and id="toolpath-yz"
//     velocity    one <svg id="velocity-<axis>"> per axis, mm/s or deg/s
//     thermal     <svg id="temperatures"> (dashed target lines), and
//                 <svg id="heater-duty"> (percent) when a duty signal is given
//     servos      <svg id="servos">, degrees
//     timing      only with profiled MCUs (run --profile): per MCU a <ul class="timing-facts">
//                 and <table class="timing" id="timing-<mcu>"> of vectors (html/ReportTiming.cpp)
//     transcript  <pre id="transcript">, lines class "from-host" / "from-firmware",
//                 or "none"
//   A plot section without data is left out. <signal> and <axis> in ids are
//   the names with every character outside [A-Za-z0-9_-] replaced by '-'; the
//   exact name is in the svg's data-signal / data-axis attribute.
// - Every plot is <svg class="plot" id=...> with its mapping in attributes:
//   data-x-min/-max and data-y-min/-max (the data range of the plot area, time
//   plots in seconds), data-plot-left/-top/-width/-height (the plot area in
//   SVG pixels), y grows downwards. Each series is a <polyline class="series"
//   data-series="name" points="x,y ..."> in SVG pixels, one decimal. Toolpath
//   views also carry data-scale (px per mm) and data-mode ("line"/"coverage").
//
// Scales:
// - Time plots span [0, end] where end is RunReport::end_cycle's time or the
//   last event's, whichever is later. Their plot area is kTimePlotWidth wide:
//   one column per pixel.
// - Toolpath views are squares of kToolpathSide2D (two axes) or kToolpathSide3D
//   (three views) pixels, offset by kToolpathMarginLeft/Top inside the svg.
//   Both axes share one scale so shapes are true: span = the larger of the two
//   axes' extents (1 when both are 0), scale = side / (1.1 * span) px per unit,
//   and the middle of each axis' extent maps to the middle of the square
//   (horizontal axis to the right, vertical axis up).
//
// Bounds (the file stays small for runs of millions of events):
// - A time series with at most one change per pixel column is drawn exactly (a
//   step line); a denser one is reduced per column to its entering value, its
//   minimum and maximum (in the order they occur) and its leaving value: at
//   most 4 points per column, 4 * kTimePlotWidth per series. Heater duty is
//   the exception: a dense one is drawn as its time average per column (what
//   a PWM heater delivers), at most kTimePlotWidth points.
// - Velocity: per column, the average velocity over the column; each position
//   change is spread linearly over the time before it (the shorter of the
//   intervals to the previous and to the next change, at most two columns),
//   so constant-rate stepping gives its exact speed. At most kTimePlotWidth
//   points per axis, fewer when flat.
// - Toolpath: the positions simplified to a line (cone intersection): every
//   drawn vertex is a real position and every position lies within
//   kToolpathTolerancePx of the drawn line, so straight moves and a stepper's
//   staircase become one segment. A path that still needs more than
//   kMaxToolpathPoints vertices (a scribble) is drawn instead as the area it
//   covers: <path class="coverage"> of square cells from 2 px up, at most 6000
//   runs of cells, and the svg says data-mode="coverage" (else "line").
// - Findings: the first kMaxFindingRows rows, then a note of how many more.
// - Transcript: at most kTranscriptHead + kTranscriptTail lines (the first and
//   the last ones, with a note of how many were left out between), each cut at
//   kMaxTranscriptChars characters.
// - So the size does not grow with the number of events: at most about 50 kB
//   per time series, 150 kB per toolpath view, and a few hundred kB for the
//   findings table and the transcript at their limits (the 15 s demo run of
//   the tests with every section is about 100 kB; a million-event run with a
//   toolpath drawn as coverage about 80 kB).
#pragma once

#include <cstddef>
#include <string>

#include "trace/RunReport.hpp"
#include "trace/html/ReportLayout.hpp"

namespace avrbench {

// Throws std::out_of_range for a series whose signal id is not in the timeline
// (or in the golden, for a comparison).
std::string format_html_report(const RunReport& report);

// Throws std::runtime_error naming `path` when it cannot be written.
void write_html_report(const RunReport& report, const std::string& path);

}  // namespace avrbench
