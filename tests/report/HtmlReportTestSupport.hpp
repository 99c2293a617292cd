// Shared by the HTML report tests: hand-built runs with known geometry, and a
// small reader for the parts of the report the tests look at (elements by id,
// attributes, polyline points).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "parts/StepDirDriver.hpp"
#include "trace/RunReport.hpp"
#include "trace/Timeline.hpp"

namespace avrbench::report_test {

constexpr std::uint32_t kClock = 16000000;
constexpr double kStepMm = 1.0 / 80;  // 80 steps/mm

// Steps one axis from `from_mm` to `to_mm` at `speed_mm_s`, starting at
// `start_cycle`, one event per step; returns the cycle of the last step.
inline Cycle record_move(Timeline& timeline, SignalId axis, Cycle start_cycle, double from_mm, double to_mm,
                         double speed_mm_s) {
    const long steps = std::lround(std::fabs(to_mm - from_mm) / kStepMm);
    const double direction = to_mm > from_mm ? 1.0 : -1.0;
    const auto period = static_cast<Cycle>(std::llround(kStepMm / speed_mm_s * kClock));
    Cycle cycle = start_cycle;
    for (long k = 1; k <= steps; ++k) {
        cycle += period;
        timeline.record_real(axis, cycle, from_mm + direction * static_cast<double>(k) * kStepMm);
    }
    return cycle;
}

// A 20 mm square on x/y: +X at 10 mm/s (0..2 s), +Y at 5 mm/s (2..6 s),
// -X at 10 mm/s (6..8 s), -Y at 5 mm/s (8..12 s). Optionally z moves at the
// end (0 -> 5 mm at 2 mm/s, 12..14.5 s), and a heater, a servo.
struct DemoRun {
    std::unique_ptr<Timeline> timeline = std::make_unique<Timeline>();
    SignalId x = 0, y = 0, z = 0, hotend = 0, duty = 0, servo = 0, step = 0;
    RunReport report;
};

inline DemoRun square_run(bool with_z = false) {
    DemoRun run;
    Timeline& t = *run.timeline;
    run.x = t.add_signal({"x_axis", "position_mm", SignalKind::Real, 64, kClock});
    run.y = t.add_signal({"y_axis", "position_mm", SignalKind::Real, 64, kClock});
    t.record_real(run.x, 0, 0);
    t.record_real(run.y, 0, 0);
    Cycle c = record_move(t, run.x, 0, 0, 20, 10);
    c = record_move(t, run.y, c, 0, 20, 5);
    c = record_move(t, run.x, c, 20, 0, 10);
    c = record_move(t, run.y, c, 20, 0, 5);
    run.report.title = "square toolpath";
    run.report.timeline = run.timeline.get();
    run.report.end_cycle = 12ULL * kClock;
    run.report.axes = {{"x", run.x, false}, {"y", run.y, false}};
    if (with_z) {
        run.z = t.add_signal({"z_axis", "position_mm", SignalKind::Real, 64, kClock});
        t.record_real(run.z, 0, 0);
        record_move(t, run.z, c, 0, 5, 2);
        run.report.end_cycle = 15ULL * kClock;
        run.report.axes.push_back({"z", run.z, false});
    }
    return run;
}

// Adds a hotend heating towards 210 degC with a bang-bang duty, a servo
// sweeping 0..90 deg, a transcript, two findings and a failed comparison on a
// step wire whose pulses lag by 40 cycles from the 50th on.
inline void add_everything(DemoRun& run) {
    Timeline& t = *run.timeline;
    const double end_s = static_cast<double>(run.report.end_cycle) / kClock;
    run.hotend = t.add_signal({"hotend", "temp_degC", SignalKind::Real, 64, kClock});
    run.duty = t.add_signal({"hotend", "duty", SignalKind::Real, 64, kClock});
    run.servo = t.add_signal({"servo0", "angle_deg", SignalKind::Real, 64, kClock});
    run.step = t.add_signal({"mcu", "PD2", SignalKind::Wire, 1, kClock});
    double temp = 22;
    for (int i = 0; i <= 1000; ++i) {
        const double s = end_s * i / 1000;
        const bool on = temp < 210;
        temp += on ? (230 - temp) * 0.02 : (22 - temp) * 0.01;
        const auto cycle = static_cast<Cycle>(s * kClock);
        t.record_real(run.hotend, cycle, temp);
        t.record_real(run.duty, cycle, on ? 1.0 : 0.0);
        t.record_real(run.servo, cycle, 45 + 45 * std::sin(s));
    }
    Timeline golden;
    const SignalId gstep = golden.add_signal({"mcu", "PD2", SignalKind::Wire, 1, kClock});
    for (Cycle k = 0; k < 200; ++k) {
        golden.record(gstep, 1000 + k * 2000, 1);
        golden.record(gstep, 1000 + k * 2000 + 64, 0);
        const Cycle lag = k >= 50 ? 40 : 0;
        t.record(run.step, 1000 + k * 2000 + lag, 1);
        t.record(run.step, 1000 + k * 2000 + lag + 64, 0);
    }
    ComparisonView cmp;
    cmp.passed = false;
    cmp.golden = std::move(golden);
    cmp.first_divergence_signal = "mcu.PD2";
    cmp.first_divergence_cycle = 1000 + 50 * 2000 + 40;
    // Several lines, as CompareResult::report() writes them.
    cmp.summary = "FAIL: 1 of 3 channels differ from the golden timeline\n"
                  "first divergence: mcu.PD2: rising edge 51 at cycle 101040, golden 101000 (+40 cycles > tolerance 8)\n";
    cmp.channels = {{"mcu.PD2", "timing", "150 edges late by 40 cycles"}, {"mcu.PD5", "ok", ""}};
    run.report.comparison = std::move(cmp);

    TemperatureSeries hotend;
    hotend.name = "hotend";
    hotend.temperature_degC = run.hotend;
    hotend.duty = run.duty;
    hotend.target_degC = 210.0;
    run.report.temperatures = {hotend};
    run.report.servos = {{"servo0", run.servo}};
    run.report.facts = {"firmware: build/firmware/demo.elf", "board: uno-cnc-shield", "simulated: 15 s"};
    for (int i = 0; i < 12; ++i) {
        run.report.transcript.push_back({static_cast<Cycle>(i) * 800000, kClock, true, "G1 X" + std::to_string(i)});
        run.report.transcript.push_back({static_cast<Cycle>(i) * 800000 + 4000, kClock, false, "ok"});
    }
    Finding crash{Mcu::kStackOverflow, "mcu", 1234567, kClock, true, 0x1a4, "recurse+0x6",
                  "SP 0x0213 below __bss_end 0x0300"};
    Finding part{StepDirDriver::kStepHighTooShort, "x_driver", 2000000, kClock, false, 0, "", "STEP high 0.5 us < 1.0 us"};
    run.report.findings = {crash, part};
}

// ---------------------------------------------------------------- reading the report

// The text of the element <tag ... id="id" ...> ... </tag> (same tags not nested), or "".
inline std::string element(const std::string& html, const std::string& tag, const std::string& id) {
    const std::string needle = "id=\"" + id + "\"";
    std::size_t pos = 0;
    while ((pos = html.find("<" + tag, pos)) != std::string::npos) {
        const std::size_t close = html.find('>', pos);
        if (close == std::string::npos) return "";
        if (html.substr(pos, close - pos).find(needle) != std::string::npos) {
            const std::size_t end = html.find("</" + tag + ">", close);
            if (end == std::string::npos) return "";
            return html.substr(pos, end + tag.size() + 3 - pos);
        }
        pos = close;
    }
    return "";
}

// The value of attribute `name` in the first tag of `text`, or nullopt.
inline std::optional<std::string> attribute(const std::string& text, const std::string& name) {
    const std::size_t close = text.find('>');
    const std::string head = text.substr(0, close);
    const std::string needle = " " + name + "=\"";
    const std::size_t pos = head.find(needle);
    if (pos == std::string::npos) return std::nullopt;
    const std::size_t start = pos + needle.size();
    return head.substr(start, head.find('"', start) - start);
}

inline double number_attribute(const std::string& text, const std::string& name) {
    const auto value = attribute(text, name);
    EXPECT_TRUE(value.has_value()) << "no " << name << " in " << text.substr(0, 300);
    return value ? std::stod(*value) : 0.0;
}

using Points = std::vector<std::pair<double, double>>;

// The points of the polyline with data-series="series" inside `svg`.
inline Points polyline(const std::string& svg, const std::string& series) {
    const std::size_t pos = svg.find("<polyline class=\"series\" data-series=\"" + series + "\"");
    if (pos == std::string::npos) return {};
    const auto points = attribute(svg.substr(pos), "points");
    Points out;
    if (!points) return out;
    std::istringstream in(*points);
    std::string pair;
    while (in >> pair) {
        const auto comma = pair.find(',');
        out.emplace_back(std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1)));
    }
    return out;
}

// The polyline's y at pixel column x (linear between its points), or nullopt
// outside it. At a vertical segment, the first point's y.
inline std::optional<double> y_at(const Points& points, double x) {
    for (std::size_t i = 1; i < points.size(); ++i) {
        const auto& [x0, y0] = points[i - 1];
        const auto& [x1, y1] = points[i];
        if (x < x0 || x > x1) continue;
        if (x1 == x0) return y0;
        return y0 + (y1 - y0) * (x - x0) / (x1 - x0);
    }
    return std::nullopt;
}

// Maps plot pixels back to data through the svg's data-* attributes.
struct PlotMapping {
    double x_min, x_max, y_min, y_max, left, top, width, height;
    explicit PlotMapping(const std::string& svg)
        : x_min(number_attribute(svg, "data-x-min")), x_max(number_attribute(svg, "data-x-max")),
          y_min(number_attribute(svg, "data-y-min")), y_max(number_attribute(svg, "data-y-max")),
          left(number_attribute(svg, "data-plot-left")), top(number_attribute(svg, "data-plot-top")),
          width(number_attribute(svg, "data-plot-width")), height(number_attribute(svg, "data-plot-height")) {}
    double data_x(double px) const { return x_min + (px - left) / width * (x_max - x_min); }
    double data_y(double py) const { return y_max - (py - top) / height * (y_max - y_min); }
    double pixel_x(double x) const { return left + (x - x_min) / (x_max - x_min) * width; }
    double pixel_y(double y) const { return top + (y_max - y) / (y_max - y_min) * height; }
};

// Checks that every element opened is closed in order (HTML void elements and
// self-closed SVG elements excepted). Returns "" or the first problem.
inline std::string nesting_problem(const std::string& html) {
    static const std::vector<std::string> kVoid = {"meta", "br", "hr", "img", "input", "link", "wbr", "col"};
    std::vector<std::string> stack;
    std::size_t pos = 0;
    while ((pos = html.find('<', pos)) != std::string::npos) {
        if (html.compare(pos, 2, "<!") == 0) {
            pos = html.find('>', pos);
            continue;
        }
        const std::size_t close = html.find('>', pos);
        if (close == std::string::npos) return "unterminated tag at " + std::to_string(pos);
        std::string tag = html.substr(pos + 1, close - pos - 1);
        const bool closing = !tag.empty() && tag[0] == '/';
        const bool self_closed = !tag.empty() && tag.back() == '/';
        if (closing) tag.erase(0, 1);
        const std::string name = tag.substr(0, tag.find_first_of(" \t\n/"));
        if (closing) {
            if (stack.empty() || stack.back() != name)
                return "</" + name + "> at " + std::to_string(pos) + " closes <" + (stack.empty() ? "" : stack.back()) + ">";
            stack.pop_back();
        } else if (!self_closed && std::find(kVoid.begin(), kVoid.end(), name) == kVoid.end()) {
            stack.push_back(name);
            if (name == "style") {  // raw text
                pos = html.find("</style>", close);
                continue;
            }
        }
        pos = close + 1;
    }
    if (!stack.empty()) return "<" + stack.back() + "> never closed";
    return "";
}

inline std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + what.size())) ++n;
    return n;
}

}  // namespace avrbench::report_test
