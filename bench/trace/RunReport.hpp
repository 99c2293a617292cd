// Everything an HTML report shows about one run, gathered by whoever ran it
// (the CLI, a scenario) from the board, the host and the comparison. Plain
// data: the report writer (HtmlReport) depends on nothing else.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/Finding.hpp"
#include "trace/Timeline.hpp"

namespace avrbench {

// Which timeline signals mean what, so the report can plot them.
struct AxisSeries {
    std::string name;          // "x"
    SignalId position;         // real signal: position in mm (linear) or degrees (rotary)
    bool rotary = false;
};

struct TemperatureSeries {
    std::string name;                       // "hotend"
    SignalId temperature_degC;              // real: the heated block
    std::optional<SignalId> sensor_degC;    // real: what the thermistor sees (lags the block)
    std::optional<SignalId> heater_on;      // wire: the heater gate; its time average is the duty
    std::optional<SignalId> duty;           // real 0..1 per sample window (used when heater_on is absent)
    std::optional<double> target_degC;      // a fixed target
    // Targets set during the run (M104/M109/M140/M190 S..): (time [s], degC).
    std::vector<std::pair<double, double>> target_steps;
};

// A fault injected into a part, drawn as a marker on the time plots.
struct FaultMarker {
    double t_s = 0;
    Cycle cycle = 0;
    std::string label;  // "heater: disconnected"
};

struct ServoSeries {
    std::string name;
    SignalId angle_deg;  // real
};

struct TranscriptLine {
    Cycle cycle = 0;
    std::uint32_t clock_hz = 16000000;
    bool from_host = true;  // host -> firmware, else firmware -> host
    std::string text;
};

// A failed (or passed) comparison against a golden timeline, in terms the
// report can draw: the golden's events next to the actual ones, and where the
// first divergence is.
struct ComparisonView {
    bool passed = true;
    Timeline golden;                   // same signal names as the actual timeline where they match
    std::string first_divergence_signal;  // "uno.PD2"; empty if none
    Cycle first_divergence_cycle = 0;
    std::uint32_t first_divergence_clock_hz = 16000000;
    std::string summary;               // one paragraph, plain text
    struct ChannelRow {
        std::string signal;
        std::string verdict;   // "ok", "timing", "missing", "new", ...
        std::string detail;
    };
    std::vector<ChannelRow> channels;
};

// One MCU's timing profile (mcu/TimingProfile.hpp), as the report shows it.
struct TimingTable {
    std::string mcu;
    std::vector<std::string> facts;  // CPU load, stack, interrupts off: one line each
    struct Row {
        int vector = 0;
        std::uint64_t runs = 0;
        int max_depth = 0;
        std::array<Cycle, 4> inclusive{}, exclusive{}, latency{};  // min, median, p99, max
    };
    std::vector<Row> rows;
};

// A display's screens over time (an LCD's: each burst of writes one screen).
struct DisplayScreens {
    std::string part;  // "lcd"
    std::uint32_t clock_hz = 16000000;
    std::vector<std::pair<Cycle, std::vector<std::string>>> screens;  // the cycle of each screen's last write
};

struct RunReport {
    std::string title;               // "stepdir_test on arduino-uno-cnc-shield-v3"
    std::vector<std::string> facts;  // "firmware: build/firmware/x.elf (sha256 ...)", "simulated: 1.2 s", ...
    const Timeline* timeline = nullptr;
    Cycle end_cycle = 0;
    std::uint32_t end_clock_hz = 16000000;
    std::vector<AxisSeries> axes;             // 2 or 3 linear axes give the XY(Z) toolpath
    std::vector<TemperatureSeries> temperatures;
    std::vector<ServoSeries> servos;
    std::vector<TranscriptLine> transcript;
    std::vector<FaultMarker> faults;
    std::vector<Finding> findings;
    std::optional<ComparisonView> comparison;
    std::vector<TimingTable> timing;  // the profiled MCUs (run --profile); none: no section
    std::vector<DisplayScreens> displays;  // parts that show text; none: no section
};

}  // namespace avrbench
