// The HTML report's fixed sizes and limits (what trace/HtmlReport.hpp
// promises about them), shared by the report's section writers below it.
#pragma once

#include <cstddef>
#include <string>

namespace avrbench {

namespace html_report {
inline constexpr int kTimePlotWidth = 900;        // plot area of time plots, px (one column per px)
inline constexpr int kTimePlotMarginLeft = 72;    // y tick labels and axis label
inline constexpr int kTimePlotMarginRight = 24;
inline constexpr int kTimePlotMarginTop = 30;     // legend row
inline constexpr int kTimePlotMarginBottom = 42;  // time ticks and axis label
inline constexpr int kToolpathSide2D = 440;
inline constexpr int kToolpathSide3D = 260;
inline constexpr int kToolpathMarginLeft = 56;
inline constexpr int kToolpathMarginTop = 30;
inline constexpr int kToolpathMarginRight = 12;
inline constexpr int kToolpathMarginBottom = 44;
inline constexpr std::size_t kMaxToolpathPoints = 8000;
inline constexpr double kToolpathTolerancePx = 0.25;
inline constexpr std::size_t kMaxFindingRows = 500;
inline constexpr std::size_t kTranscriptHead = 200;
inline constexpr std::size_t kTranscriptTail = 200;
inline constexpr std::size_t kMaxTranscriptChars = 240;
inline constexpr std::size_t kMaxComparisonPlots = 6;

// "uno.PD2" -> "uno-PD2": the form names take in element ids.
std::string id_fragment(const std::string& name);
}  // namespace html_report

}  // namespace avrbench
