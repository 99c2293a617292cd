// The HTML report: plots land where the documented scales put them, velocity
// levels are the hand-computed step rates, all text is escaped, empty sections
// say so, a failed comparison is drawn around its divergence, and the file
// stays small for a million events.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "stimulus/UartHost.hpp"
#include "report/HtmlReportTestSupport.hpp"
#include "trace/HtmlReport.hpp"
#include "trace/TraceTestSupport.hpp"
#include "printer3d/PrinterBench.hpp"

namespace avrbench {
namespace {

using namespace report_test;
namespace layout = html_report;

TEST(HtmlReport, SquareToolpathCornersLandOnTheDocumentedPixels) {
    const DemoRun run = square_run();
    const std::string html = format_html_report(run.report);
    const std::string svg = element(html, "svg", "toolpath");
    ASSERT_FALSE(svg.empty());
    EXPECT_EQ(attribute(svg, "class"), "plot toolpath");

    // Documented scale: span 20 mm, scale = side / (1.1 * 20) px/mm, the
    // middle of each extent (10 mm) at the middle of the square, y up.
    const double side = layout::kToolpathSide2D;
    const double scale = side / (1.1 * 20);
    EXPECT_DOUBLE_EQ(number_attribute(svg, "data-scale"), scale);
    auto px = [&](double x_mm) { return layout::kToolpathMarginLeft + side / 2 + (x_mm - 10) * scale; };
    auto py = [&](double y_mm) { return layout::kToolpathMarginTop + side / 2 - (y_mm - 10) * scale; };

    const Points path = polyline(svg, "path");
    // 6400 step events collapse to the square's five corners (start = end).
    ASSERT_EQ(path.size(), 5u) << svg.substr(0, 2000);
    const double corners[5][2] = {{0, 0}, {20, 0}, {20, 20}, {0, 20}, {0, 0}};
    // Each drawn corner is within the simplification tolerance (+ 0.05 px of
    // rounding) of the true one. With 440 px the corners are round numbers:
    // (76,450) (476,450) (476,50) (76,50).
    EXPECT_EQ(attribute(svg, "data-mode"), "line");
    const double tolerance = layout::kToolpathTolerancePx + 0.05;
    for (std::size_t i = 0; i < 5; ++i) {
        EXPECT_NEAR(path[i].first, px(corners[i][0]), tolerance) << "corner " << i;
        EXPECT_NEAR(path[i].second, py(corners[i][1]), tolerance) << "corner " << i;
    }
    EXPECT_DOUBLE_EQ(px(20), 476);
    EXPECT_DOUBLE_EQ(py(20), 50);

    // Tick labels and axis labels with units.
    EXPECT_NE(svg.find(">x [mm]</text>"), std::string::npos);
    EXPECT_NE(svg.find(">y [mm]</text>"), std::string::npos);
    EXPECT_NE(svg.find(">20</text>"), std::string::npos);
    // Two axes: no side views.
    EXPECT_EQ(element(html, "svg", "toolpath-xz"), "");
}

TEST(HtmlReport, ToolpathKeepsAMoveThatTurnsBackOnItself) {
    // x 0 -> 20 -> 10 along one line, then y 0 -> 20: the turn at x = 20 must be drawn.
    DemoRun run;
    Timeline& t = *run.timeline;
    run.x = t.add_signal({"x_axis", "position_mm", SignalKind::Real, 64, kClock});
    run.y = t.add_signal({"y_axis", "position_mm", SignalKind::Real, 64, kClock});
    t.record_real(run.x, 0, 0);
    t.record_real(run.y, 0, 0);
    Cycle c = record_move(t, run.x, 0, 0, 20, 10);
    c = record_move(t, run.x, c, 20, 10, 10);
    record_move(t, run.y, c, 0, 20, 10);
    run.report.timeline = run.timeline.get();
    run.report.axes = {{"x", run.x, false}, {"y", run.y, false}};
    const std::string svg = element(format_html_report(run.report), "svg", "toolpath");
    const Points path = polyline(svg, "path");
    ASSERT_EQ(path.size(), 4u) << svg;
    const double side = layout::kToolpathSide2D, scale = side / 22;
    const double tolerance = layout::kToolpathTolerancePx + 0.05;
    EXPECT_NEAR(path[1].first, layout::kToolpathMarginLeft + side / 2 + 10 * scale, tolerance);
    EXPECT_NEAR(path[2].first, layout::kToolpathMarginLeft + side / 2, tolerance);
    EXPECT_NEAR(path[3].second, layout::kToolpathMarginTop + side / 2 - 10 * scale, tolerance);
}

TEST(HtmlReport, VelocityPlotLevelsAreTheStepRates) {
    const DemoRun run = square_run();
    const std::string html = format_html_report(run.report);
    struct Expect {
        double t0, t1, v;
    };
    // x: +10 mm/s for 0..2 s, 0 while y moves, -10 mm/s 6..8 s. y: +5 2..6 s, -5 8..12 s.
    const std::vector<std::pair<std::string, std::vector<Expect>>> axes = {
        {"x", {{0.05, 1.95, 10}, {2.05, 5.95, 0}, {6.05, 7.95, -10}, {8.05, 11.95, 0}}},
        {"y", {{0.05, 1.95, 0}, {2.05, 5.95, 5}, {6.05, 7.95, 0}, {8.05, 11.95, -5}}}};
    for (const auto& [axis, expects] : axes) {
        const std::string svg = element(html, "svg", "velocity-" + axis);
        ASSERT_FALSE(svg.empty()) << axis;
        EXPECT_EQ(attribute(svg, "data-axis"), axis);
        const PlotMapping map(svg);
        EXPECT_DOUBLE_EQ(map.x_min, 0);
        EXPECT_DOUBLE_EQ(map.x_max, 12);
        EXPECT_EQ(map.width, layout::kTimePlotWidth);
        const Points points = polyline(svg, axis + " velocity [mm/s]");
        ASSERT_GE(points.size(), 8u) << axis;
        EXPECT_LE(points.size(), static_cast<std::size_t>(layout::kTimePlotWidth));
        const double tolerance = 0.06 / map.height * (map.y_max - map.y_min);  // 0.06 px
        // Flat runs are drawn as one segment: read the line at every pixel column of each phase.
        for (const Expect& e : expects) {
            for (double px = std::ceil(map.pixel_x(e.t0)); px <= map.pixel_x(e.t1); px += 1) {
                const auto y = y_at(points, px);
                ASSERT_TRUE(y.has_value()) << axis << " has no line at " << map.data_x(px) << " s";
                EXPECT_NEAR(map.data_y(*y), e.v, tolerance) << axis << " at " << map.data_x(px) << " s";
            }
        }
        // The level is exactly the step rate: 80 steps/mm every 1.25 ms (x) or 2.5 ms (y).
        EXPECT_NEAR(map.data_y(points.front().second), axis == "x" ? 10.0 : 0.0, tolerance);
        EXPECT_NE(svg.find("[mm/s]</text>"), std::string::npos);
        EXPECT_NE(svg.find(">time [s]</text>"), std::string::npos);
    }
}

TEST(HtmlReport, ThreeAxesGiveTopFrontAndSideViews) {
    const DemoRun run = square_run(true);
    const std::string html = format_html_report(run.report);
    for (const char* id : {"toolpath", "toolpath-xz", "toolpath-yz"}) {
        const std::string svg = element(html, "svg", id);
        ASSERT_FALSE(svg.empty()) << id;
        EXPECT_EQ(number_attribute(svg, "data-plot-width"), layout::kToolpathSide3D) << id;
        EXPECT_GE(polyline(svg, "path").size(), 2u) << id;
    }
    // XZ: x spans 20 mm, z 5 mm; z rises at x = 0 from 0 to 5 mm (y is 0 by then).
    const std::string xz = element(html, "svg", "toolpath-xz");
    const Points path = polyline(xz, "path");
    const double side = layout::kToolpathSide3D, scale = side / 22;
    const double x0 = layout::kToolpathMarginLeft + side / 2 - 10 * scale;
    const double z5 = layout::kToolpathMarginTop + side / 2 - (5 - 2.5) * scale;
    EXPECT_NEAR(path.back().first, x0, layout::kToolpathTolerancePx + 0.05);
    EXPECT_NEAR(path.back().second, z5, layout::kToolpathTolerancePx + 0.05);
    EXPECT_NE(element(html, "svg", "velocity-z"), "");
}

TEST(HtmlReport, IsWellNestedSelfContainedAndHasEverySection) {
    DemoRun run = square_run(true);
    add_everything(run);
    const std::string html = format_html_report(run.report);
    EXPECT_EQ(nesting_problem(html), "");
    EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
    // No network, no script: the only URL is the SVG namespace, url() only to clip paths.
    EXPECT_EQ(count(html, "http:"), count(html, "xmlns=\"http://www.w3.org/2000/svg\""));
    EXPECT_EQ(count(html, "https:"), 0u);
    EXPECT_EQ(count(html, "//"), count(html, "http://www.w3.org/2000/svg"));
    EXPECT_EQ(count(html, "<script"), 0u);
    EXPECT_EQ(count(html, " src="), 0u);
    EXPECT_EQ(count(html, "url("), count(html, "url(#"));
    EXPECT_NE(html.find("default-src 'none'"), std::string::npos);

    for (const char* id : {"findings-section", "comparison-section", "toolpath-section", "velocity-section",
                           "thermal-section", "servo-section", "transcript-section"})
        EXPECT_NE(element(html, "section", id), "") << id;
    for (const char* id : {"toolpath", "toolpath-xz", "toolpath-yz", "velocity-x", "velocity-y", "velocity-z",
                           "temperatures", "heater-duty", "servos", "comparison-mcu-PD2", "comparison-mcu-PD2-overview"}) {
        const std::string svg = element(html, "svg", id);
        ASSERT_NE(svg, "") << id;
        EXPECT_EQ(attribute(svg, "class").value_or("").rfind("plot", 0), 0u) << id;
        EXPECT_EQ(nesting_problem(svg), "") << id;
        EXPECT_NE(svg.find("<g class=\"legend\">"), std::string::npos) << id;
        EXPECT_NE(svg.find("class=\"axis-label\""), std::string::npos) << id;
    }
    EXPECT_NE(element(html, "table", "findings"), "");
    EXPECT_NE(element(html, "table", "comparison-channels"), "");
    EXPECT_NE(element(html, "pre", "transcript"), "");
    EXPECT_NE(element(html, "ul", "facts").find("board: uno-cnc-shield"), std::string::npos);
    // Sections in the documented order.
    EXPECT_LT(html.find("id=\"findings-section\""), html.find("id=\"comparison-section\""));
    EXPECT_LT(html.find("id=\"comparison-section\""), html.find("id=\"toolpath-section\""));
    EXPECT_LT(html.find("id=\"servo-section\""), html.find("id=\"transcript-section\""));
}

TEST(HtmlReport, ThermalPlotDrawsTheTargetLineAndTheDutyInPercent) {
    DemoRun run = square_run();
    add_everything(run);
    const std::string html = format_html_report(run.report);
    const std::string svg = element(html, "svg", "temperatures");
    ASSERT_NE(svg, "");
    const PlotMapping map(svg);
    const std::size_t target = svg.find("<line class=\"target\"");
    ASSERT_NE(target, std::string::npos);
    EXPECT_NEAR(number_attribute(svg.substr(target), "y1"), map.pixel_y(210), 0.06);
    EXPECT_NE(svg.find("hotend target 210.0 \xc2\xb0" "C"), std::string::npos);
    const Points temp = polyline(svg, "hotend block");
    ASSERT_GE(temp.size(), 10u);
    EXPECT_NEAR(map.data_y(temp.front().second), 22 + (230 - 22) * 0.02, 0.2);
    EXPECT_NE(svg.find("temperature [\xc2\xb0" "C]"), std::string::npos);

    const std::string duty = element(html, "svg", "heater-duty");
    ASSERT_NE(duty, "");
    const PlotMapping dmap(duty);
    // 0..100 % with 5 % of margin each side: 100 % lies inside the frame.
    EXPECT_DOUBLE_EQ(dmap.y_min, -5);
    EXPECT_DOUBLE_EQ(dmap.y_max, 105);
    const Points d = polyline(duty, "hotend heater");
    ASSERT_GE(d.size(), 4u);
    EXPECT_NEAR(dmap.data_y(d.front().second), 100, 0.2);  // heats from the start
    EXPECT_GT(d.front().second, dmap.top + 1.0);           // below the frame's top edge, visible
    EXPECT_NE(duty.find("duty [%]"), std::string::npos);
    EXPECT_NE(element(html, "svg", "servos").find("angle [deg]"), std::string::npos);
}

TEST(HtmlReport, FailedComparisonOverlaysGoldenAndActualAroundTheDivergence) {
    DemoRun run = square_run();
    add_everything(run);
    const std::string html = format_html_report(run.report);
    EXPECT_NE(html.find("golden: FAILED"), std::string::npos);
    const std::string summary = element(html, "pre", "comparison-summary");
    EXPECT_NE(summary.find("FAIL: "), std::string::npos);
    // Real line breaks, not the escaped text of one.
    EXPECT_NE(summary.find("\nfirst divergence: "), std::string::npos) << summary;
    EXPECT_EQ(summary.find("\\x0a"), std::string::npos) << summary;
    EXPECT_NE(summary.find("+40 cycles &gt; tolerance 8"), std::string::npos);
    const std::string channels = element(html, "table", "comparison-channels");
    EXPECT_NE(channels.find("<tr class=\"diverged\"><td class=\"mono\">mcu.PD2</td><td class=\"verdict\">timing"),
              std::string::npos);
    EXPECT_NE(channels.find("<tr class=\"ok\"><td class=\"mono\">mcu.PD5"), std::string::npos);

    const std::string svg = element(html, "svg", "comparison-mcu-PD2");
    ASSERT_NE(svg, "");
    EXPECT_EQ(attribute(svg, "data-signal"), "mcu.PD2");
    const PlotMapping map(svg);
    const double divergence = 101040.0 / kClock, golden_edge = 101000.0 / kClock;
    // Zoomed: the window holds the divergence and is a small part of the 12 s run.
    EXPECT_LT(map.x_min, divergence);
    EXPECT_GT(map.x_max, divergence);
    EXPECT_LT(map.x_max - map.x_min, 0.005);
    // The marker: a vertical line at the divergence, with a label.
    const std::size_t line = svg.find("<line class=\"divergence\"");
    ASSERT_NE(line, std::string::npos);
    EXPECT_NEAR(number_attribute(svg.substr(line), "x1"), map.pixel_x(divergence), 0.06);
    EXPECT_NEAR(number_attribute(svg.substr(line), "x2"), map.pixel_x(divergence), 0.06);
    EXPECT_NE(svg.find(">first divergence 0.006315 s</text>"), std::string::npos);
    // Both waveforms, each with its rising edge where it should be.
    auto has_edge_at = [&](const Points& points, double t) {
        for (std::size_t i = 1; i < points.size(); ++i)
            if (std::fabs(points[i].first - map.pixel_x(t)) < 0.06 && points[i - 1].first == points[i].first &&
                points[i].second < points[i - 1].second)
                return true;
        return false;
    };
    const Points golden = polyline(svg, "golden"), actual = polyline(svg, "actual");
    ASSERT_GE(golden.size(), 8u);
    ASSERT_GE(actual.size(), 8u);
    EXPECT_TRUE(has_edge_at(golden, golden_edge));
    EXPECT_TRUE(has_edge_at(actual, divergence));
    EXPECT_FALSE(has_edge_at(actual, golden_edge));
    // The close-up: six times the 24 cycles to the nearest other edge (golden's
    // fall at 101064) each side, both rising edges far apart on screen.
    const std::string detail = element(html, "svg", "comparison-mcu-PD2-detail");
    ASSERT_NE(detail, "");
    const PlotMapping dmap(detail);
    EXPECT_NEAR(dmap.x_min, (101040.0 - 144) / kClock, 1e-12);
    EXPECT_NEAR(dmap.x_max, (101040.0 + 144) / kClock, 1e-12);
    EXPECT_GT(dmap.pixel_x(divergence) - dmap.pixel_x(golden_edge), 100);
    const std::size_t dline = detail.find("<line class=\"divergence\"");
    ASSERT_NE(dline, std::string::npos);
    EXPECT_NEAR(number_attribute(detail.substr(dline), "x1"), dmap.pixel_x(divergence), 0.06);
    const Points dgolden = polyline(detail, "golden"), dactual = polyline(detail, "actual");
    auto has_rise = [](const Points& points, double px) {
        for (std::size_t i = 1; i < points.size(); ++i)
            if (std::fabs(points[i].first - px) < 0.06 && points[i - 1].first == points[i].first &&
                points[i].second < points[i - 1].second)
                return true;
        return false;
    };
    EXPECT_TRUE(has_rise(dgolden, dmap.pixel_x(golden_edge)));
    EXPECT_TRUE(has_rise(dactual, dmap.pixel_x(divergence)));

    // The overview spans the run, with the zoom window shaded.
    const std::string overview = element(html, "svg", "comparison-mcu-PD2-overview");
    ASSERT_NE(overview, "");
    EXPECT_DOUBLE_EQ(PlotMapping(overview).x_min, 0);
    EXPECT_NE(overview.find("class=\"zoom-window\""), std::string::npos);
    // An ok channel gets no plot.
    EXPECT_EQ(element(html, "svg", "comparison-mcu-PD5"), "");
}

TEST(HtmlReport, PassedComparisonShowsTheTableWithoutPlots) {
    DemoRun run = square_run();
    ComparisonView cmp;
    cmp.passed = true;
    cmp.summary = "all 2 channels within tolerance";
    cmp.channels = {{"mcu.PD2", "ok", ""}, {"mcu.PD5", "ok", ""}};
    run.report.comparison = std::move(cmp);
    const std::string html = format_html_report(run.report);
    EXPECT_NE(html.find("golden: passed"), std::string::npos);
    EXPECT_NE(element(html, "table", "comparison-channels"), "");
    EXPECT_EQ(html.find("id=\"comparison-mcu"), std::string::npos);
}

// A UART that sent different bytes is shown as text, golden above actual,
// the first differing byte marked, not plotted as a number.
TEST(HtmlReport, DifferingUartBytesAreShownAsTextWithTheFirstDifferenceMarked) {
    DemoRun run = square_run();
    Timeline& t = *run.timeline;
    const SignalId tx = t.add_signal({"mcu", "uart0_tx", SignalKind::Bus, 8, kClock, true});
    Timeline golden;
    const SignalId gtx = golden.add_signal({"mcu", "uart0_tx", SignalKind::Bus, 8, kClock, true});
    const std::string expected = "ok\r\nok\r\n", actual = "ok\r\nerror:1\r\n";
    for (std::size_t i = 0; i < expected.size(); ++i) golden.record(gtx, 1000 + i * 1360, static_cast<std::uint8_t>(expected[i]));
    for (std::size_t i = 0; i < actual.size(); ++i) t.record(tx, 1000 + i * 1360, static_cast<std::uint8_t>(actual[i]));
    ComparisonView cmp;
    cmp.passed = false;
    cmp.golden = std::move(golden);
    cmp.first_divergence_signal = "mcu.uart0_tx";
    cmp.first_divergence_cycle = 1000 + 4 * 1360;
    cmp.summary = "FAIL: 1 of 1 channels differ from the golden timeline\n";
    cmp.channels = {{"mcu.uart0_tx", "differs", "byte 5"}};
    run.report.comparison = std::move(cmp);
    run.report.timeline = run.timeline.get();
    const std::string html = format_html_report(run.report);
    const std::string table = element(html, "table", "comparison-mcu-uart0_tx");
    ASSERT_NE(table, "") << html;
    // Byte 5 (index 4) is the first that differs: 'o' in the golden, 'e' now.
    EXPECT_NE(table.find("byte 5 at"), std::string::npos) << table;
    EXPECT_NE(table.find("ok\\r\\n<mark>o</mark>k\\r\\n"), std::string::npos) << table;
    EXPECT_NE(table.find("ok\\r\\n<mark>e</mark>rror:1\\r\\n"), std::string::npos) << table;
    EXPECT_EQ(element(html, "svg", "comparison-mcu-uart0_tx"), "");  // no numeric plot
    // The summary wraps inside its card.
    EXPECT_NE(html.find("pre#comparison-summary {"), std::string::npos);
    EXPECT_NE(html.find("white-space: pre-wrap; overflow-wrap: anywhere;"), std::string::npos);
}

TEST(HtmlReport, EscapesEveryPieceOfText) {
    DemoRun run = square_run();
    run.report.title = "a & b <i>";
    run.report.facts = {"path: \"x\" 'y'"};
    run.report.transcript = {{100, kClock, false, "<script>alert(\"x\")</script>"},
                             {200, kClock, true, std::string("ctl\x01 bad\xff deg \xc2\xb0" "C")}};
    run.report.findings = {{UartHost::kHostProtocol, "host<1>", 16000, kClock, false, 0, "", "got <b>error</b> & quit"}};
    const SignalId odd = run.timeline->add_signal({"<x>", "pos&", SignalKind::Real, 64, kClock});
    run.timeline->record_real(odd, 0, 0);
    run.timeline->record_real(odd, 16000, 1);
    run.report.axes.push_back({"<z>", odd, false});

    const std::string html = format_html_report(run.report);
    EXPECT_EQ(nesting_problem(html), "");
    EXPECT_EQ(html.find("<script"), std::string::npos);
    EXPECT_EQ(html.find("<b>error"), std::string::npos);
    EXPECT_EQ(html.find("<i>"), std::string::npos);
    EXPECT_NE(html.find("&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;"), std::string::npos);
    EXPECT_NE(html.find("<title>a &amp; b &lt;i&gt;</title>"), std::string::npos);
    EXPECT_NE(html.find("path: &quot;x&quot; &#39;y&#39;"), std::string::npos);
    EXPECT_NE(html.find("got &lt;b&gt;error&lt;/b&gt; &amp; quit"), std::string::npos);
    EXPECT_NE(html.find("host&lt;1&gt;"), std::string::npos);
    // Control characters and invalid UTF-8 become \xNN; valid UTF-8 stays.
    EXPECT_NE(html.find("ctl\\x01 bad\\xff deg \xc2\xb0" "C"), std::string::npos);
    // Names in ids are reduced to [A-Za-z0-9_-], the exact name escaped beside.
    const std::string svg = element(html, "svg", "velocity--z-");
    ASSERT_NE(svg, "");
    EXPECT_EQ(attribute(svg, "data-axis"), "&lt;z&gt;");
    EXPECT_EQ(layout::id_fragment("uno.PD2"), "uno-PD2");
}

TEST(HtmlReport, EmptySectionsSayNoneOrAreLeftOut) {
    RunReport report;
    report.title = "nothing happened";
    const std::string html = format_html_report(report);
    EXPECT_EQ(nesting_problem(html), "");
    EXPECT_NE(element(html, "p", "findings-none").find(">none<"), std::string::npos);
    EXPECT_NE(element(html, "p", "transcript-none").find(">none<"), std::string::npos);
    EXPECT_NE(html.find("no findings"), std::string::npos);
    for (const char* id : {"toolpath-section", "velocity-section", "thermal-section", "servo-section", "comparison-section"})
        EXPECT_EQ(html.find(std::string("id=\"") + id + "\""), std::string::npos) << id;
    EXPECT_EQ(html.find("<svg"), std::string::npos);

    // One linear axis: velocity, but no toolpath.
    DemoRun run = square_run();
    run.report.axes.resize(1);
    const std::string one = format_html_report(run.report);
    EXPECT_EQ(one.find("id=\"toolpath\""), std::string::npos);
    EXPECT_NE(element(one, "svg", "velocity-x"), "");
    // A rotary axis joins no toolpath; its velocity is in deg/s.
    run.report.axes = {{"x", run.x, false}, {"c", run.y, true}};
    const std::string rotary = format_html_report(run.report);
    EXPECT_EQ(rotary.find("id=\"toolpath\""), std::string::npos);
    EXPECT_NE(element(rotary, "svg", "velocity-c").find("[deg/s]"), std::string::npos);
}

TEST(HtmlReport, FindingsTableHasKindSourceTimePcAndDetail) {
    DemoRun run = square_run();
    add_everything(run);
    const std::string html = format_html_report(run.report);
    const std::string table = element(html, "table", "findings");
    ASSERT_NE(table, "");
    EXPECT_EQ(count(table, "<tr class=\"finding\">"), 2u);
    EXPECT_NE(table.find("<th>kind</th><th>source</th><th>time</th><th>PC / symbol</th><th>detail</th>"),
              std::string::npos);
    EXPECT_NE(table.find(">stack-overflow</td><td>mcu</td>"), std::string::npos);
    EXPECT_NE(table.find("0.077160 s"), std::string::npos);  // 1234567 cycles at 16 MHz
    EXPECT_NE(table.find("cycle 1234567"), std::string::npos);
    EXPECT_NE(table.find("0x01a4 recurse+0x6"), std::string::npos);
    EXPECT_NE(table.find("SP 0x0213 below __bss_end 0x0300"), std::string::npos);
    EXPECT_NE(table.find(">step-high-too-short</td><td>x_driver</td>"), std::string::npos);
    EXPECT_NE(html.find("<span class=\"badge bad\">2 findings</span>"), std::string::npos);

    run.report.findings.assign(layout::kMaxFindingRows + 7, run.report.findings[0]);
    const std::string many = format_html_report(run.report);
    EXPECT_EQ(count(element(many, "table", "findings"), "<tr class=\"finding\">"), layout::kMaxFindingRows);
    // The rest counted per kind and source, as the CLI summarizes them.
    const std::string more = element(many, "p", "findings-more");
    EXPECT_NE(more.find("... and 7 more: " + std::string(to_string(run.report.findings[0].kind)) + " (" +
                        run.report.findings[0].source + ") x7"), std::string::npos) << more;
}

TEST(HtmlReport, LongTranscriptKeepsHeadAndTailWithANote) {
    RunReport report;
    for (int i = 0; i < 1000; ++i)
        report.transcript.push_back({static_cast<Cycle>(i) * 1600, kClock, i % 2 == 0, "line " + std::to_string(i) + ";"});
    report.transcript.push_back({2000000, kClock, false, std::string(1000, 'a')});
    const std::string html = format_html_report(report);
    const std::string pre = element(html, "pre", "transcript");
    ASSERT_NE(pre, "");
    EXPECT_EQ(count(pre, "\n"), layout::kTranscriptHead + layout::kTranscriptTail + 1);
    EXPECT_NE(pre.find(" line 0;"), std::string::npos);
    EXPECT_NE(pre.find(" line 199;"), std::string::npos);
    EXPECT_EQ(pre.find(" line 200;"), std::string::npos);
    EXPECT_EQ(pre.find(" line 800;"), std::string::npos);
    EXPECT_NE(pre.find(" line 801;"), std::string::npos);
    EXPECT_NE(pre.find(" line 999;"), std::string::npos);
    EXPECT_NE(pre.find("601 lines omitted (1001 in all)"), std::string::npos);
    // Direction and time on every line; a long line is cut.
    // Line 1 at cycle 1600 = 100 us at 16 MHz: both time and cycle shown.
    EXPECT_NE(pre.find("<span class=\"from-host\"><span class=\"t\">  0.000000 s           0 </span>"), std::string::npos);
    EXPECT_NE(pre.find("<span class=\"from-firmware\"><span class=\"t\">  0.000100 s        1600 </span>"), std::string::npos);
    EXPECT_NE(pre.find(std::string(layout::kMaxTranscriptChars, 'a') + "\xe2\x80\xa6"), std::string::npos);
    EXPECT_EQ(pre.find(std::string(layout::kMaxTranscriptChars + 1, 'a')), std::string::npos);
}

TEST(HtmlReport, IsByteIdenticalForIdenticalInput) {
    DemoRun a = square_run(true), b = square_run(true);
    add_everything(a);
    add_everything(b);
    const std::string first = format_html_report(a.report);
    EXPECT_EQ(first, format_html_report(a.report));
    EXPECT_EQ(first, format_html_report(b.report));
}

TEST(HtmlReport, AMillionEventsStayWithinTheSizeBound) {
    DemoRun run;
    Timeline& t = *run.timeline;
    run.x = t.add_signal({"x_axis", "position_mm", SignalKind::Real, 64, kClock});
    run.y = t.add_signal({"y_axis", "position_mm", SignalKind::Real, 64, kClock});
    run.hotend = t.add_signal({"hotend", "temp_degC", SignalKind::Real, 64, kClock});
    t.reserve_events(1'300'000);
    // A pseudo-random walk of one step on x or y every 500 cycles: 1,000,000 events.
    std::uint64_t lcg = 12345;
    long xs = 0, ys = 0;
    Cycle cycle = 0;
    for (int i = 0; i < 1'000'000; ++i) {
        lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
        const bool on_x = (lcg >> 33) & 1, up = (lcg >> 34) & 1;
        cycle += 500;
        long& steps = on_x ? xs : ys;
        steps += up ? 8 : -8;
        t.record_real(on_x ? run.x : run.y, cycle, static_cast<double>(steps) * kStepMm);
    }
    // Temperature noise: 300,000 events.
    for (int i = 0; i < 300'000; ++i) {
        lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
        t.record_real(run.hotend, static_cast<Cycle>(i) * 1666, 200 + static_cast<double>(lcg >> 40) / (1ULL << 24));
    }
    run.report.timeline = run.timeline.get();
    run.report.end_cycle = cycle;
    run.report.axes = {{"x", run.x, false}, {"y", run.y, false}};
    TemperatureSeries hotend;
    hotend.name = "hotend";
    hotend.temperature_degC = run.hotend;
    hotend.target_degC = 200.5;
    run.report.temperatures = {hotend};
    const std::string html = format_html_report(run.report);

    EXPECT_LT(html.size(), 600'000u);
    EXPECT_EQ(nesting_problem(html), "");
    // A scribble this dense is drawn as the area it covers, in bounded runs of cells.
    const std::string toolpath = element(html, "svg", "toolpath");
    EXPECT_EQ(attribute(toolpath, "data-mode"), "coverage");
    EXPECT_EQ(polyline(toolpath, "path").size(), 0u);
    const std::size_t coverage = toolpath.find("<path class=\"coverage\"");
    ASSERT_NE(coverage, std::string::npos);
    const std::string d = attribute(toolpath.substr(coverage), "d").value_or("");
    EXPECT_GT(count(d, "z"), 100u);
    EXPECT_LE(count(d, "z"), 6000u);
    // At most entering, min, max and leaving value per pixel column (step_points).
    EXPECT_LE(polyline(element(html, "svg", "velocity-x"), "x velocity [mm/s]").size(),
              4u * layout::kTimePlotWidth + 2);
    const Points temp = polyline(element(html, "svg", "temperatures"), "hotend block");
    EXPECT_GT(temp.size(), static_cast<std::size_t>(layout::kTimePlotWidth));
    EXPECT_LE(temp.size(), 4u * layout::kTimePlotWidth + 2);
    // Min/max per column keeps the noise band: values near 200 and near 201.
    const PlotMapping map(element(html, "svg", "temperatures"));
    double lo = 1e9, hi = -1e9;
    for (const auto& p : temp) lo = std::min(lo, map.data_y(p.second)), hi = std::max(hi, map.data_y(p.second));
    EXPECT_LT(lo, 200.05);
    EXPECT_GT(hi, 200.95);
}

TEST(HtmlReport, AMillionStepInfillIsDrawnAsOneSegmentPerRow) {
    // 250 rows of 50 mm on x with 0.25 mm on y, each a Bresenham staircase of
    // 4000 x steps and 20 y steps, rows alternating direction: 1,005,000 events.
    DemoRun run;
    Timeline& t = *run.timeline;
    run.x = t.add_signal({"x_axis", "position_mm", SignalKind::Real, 64, kClock});
    run.y = t.add_signal({"y_axis", "position_mm", SignalKind::Real, 64, kClock});
    t.reserve_events(1'010'000);
    t.record_real(run.x, 0, 0);
    t.record_real(run.y, 0, 0);
    long xs = 0, ys = 0;
    Cycle cycle = 0;
    for (int row = 0; row < 250; ++row) {
        const long dir = row % 2 == 0 ? 1 : -1;
        long error = 0;
        for (int k = 0; k < 4000; ++k) {
            cycle += 400;
            xs += dir;
            t.record_real(run.x, cycle, static_cast<double>(xs) * kStepMm);
            error += 20;
            if (error >= 4000 / 2) {
                error -= 4000;
                cycle += 400;
                ++ys;
                t.record_real(run.y, cycle, static_cast<double>(ys) * kStepMm);
            }
        }
    }
    ASSERT_EQ(t.events().size(), 2u + 250u * 4020u);
    run.report.timeline = run.timeline.get();
    run.report.end_cycle = cycle;
    run.report.axes = {{"x", run.x, false}, {"y", run.y, false}};
    const std::string html = format_html_report(run.report);
    EXPECT_LT(html.size(), 200'000u);
    const std::string toolpath = element(html, "svg", "toolpath");
    EXPECT_EQ(attribute(toolpath, "data-mode"), "line");
    const Points path = polyline(toolpath, "path");
    EXPECT_GE(path.size(), 251u);
    EXPECT_LE(path.size(), 2u * 251u);
    // The first row ends at x = 50 mm, y = 0.25 mm: a vertex within tolerance of it.
    const double side = layout::kToolpathSide2D, scale = number_attribute(toolpath, "data-scale");
    EXPECT_DOUBLE_EQ(scale, side / (1.1 * 62.5));
    const double want_x = layout::kToolpathMarginLeft + side / 2 + (50 - 25) * scale;
    const double want_y = layout::kToolpathMarginTop + side / 2 - (0.25 - 31.25) * scale;
    bool found = false;
    for (const auto& [x, y] : path)
        found = found || (std::fabs(x - want_x) <= 0.3 && std::fabs(y - want_y) <= 0.3);
    EXPECT_TRUE(found) << "no vertex near (" << want_x << "," << want_y << ")";
}

TEST(HtmlReport, BadSignalIdThrowsOutOfRange) {
    DemoRun run = square_run();
    run.report.servos = {{"servo", 99}};
    EXPECT_THROW(format_html_report(run.report), std::out_of_range);
}

TEST(HtmlReport, WriteThrowsNamingAnUnwritablePath) {
    trace_test::ScratchDir dir;
    const DemoRun run = square_run();
    const std::string path = dir.file("no-such-dir/report.html");
    try {
        write_html_report(run.report, path);
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    const std::string good = dir.file("report.html");
    write_html_report(run.report, good);
    EXPECT_EQ(trace_test::read_text(good), format_html_report(run.report));
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(HtmlReport, ATimingProfileIsATablePerMcuAndNoProfileNoSection) {
    RunReport r;
    r.title = "t";
    EXPECT_EQ(format_html_report(r).find("timing-section"), std::string::npos);
    TimingTable t;
    t.mcu = "uno";
    t.facts = {"cpu 0.83% executing"};
    t.rows.push_back({11, 99, 1, {28, 28, 28, 28}, {28, 28, 28, 28}, {5, 5, 5, 5}});
    r.timing.push_back(t);
    const std::string html = format_html_report(r);
    EXPECT_NE(html.find("<a href=\"#timing-section\">timing</a>"), std::string::npos);
    EXPECT_NE(html.find("<table class=\"timing\" id=\"timing-uno\">"), std::string::npos);
    EXPECT_NE(html.find("<tr><td>11</td><td>99</td><td>28</td><td>28</td><td>28</td><td>28</td><td>28</td><td>28</td>"
                        "<td>28</td><td>28</td><td>5</td><td>5</td><td>5</td><td>5</td><td>1</td></tr>"),
              std::string::npos);
    EXPECT_NE(html.find("<li>cpu 0.83% executing</li>"), std::string::npos);
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

// `run --report` streams the VCD and keeps in memory only the signals the
// report reads (Bench::report_signal_mask, Timeline::keep_when_taken). The
// printer homes X, moves, heats and idles: positions, temperatures, heater
// duty and TWI bytes all in play. A run that keeps everything and one that
// hands its events away every 10 ms keeping only the report's signals give
// the same report, byte for byte.
std::string printer_report(bool keep_only_the_reports_signals) {
    auto bench = test::printer_bench();
    bench->trace_board();
    if (keep_only_the_reports_signals) bench->timeline().keep_when_taken(bench->report_signal_mask());
    bench->host().add_lines("G28 X\nG1 X2 Y1 F600\nM104 S60\nM105\n");
    std::vector<TimelineEvent> handed_away;
    for (int slice = 0; slice < 150; ++slice) {  // 1.5 s
        bench->board().run_until_ps(static_cast<Picoseconds>(slice + 1) * 10 * kPsPerMs);
        if (keep_only_the_reports_signals) bench->timeline().take_events_into(handed_away);
    }
    return format_html_report(bench->make_report("printer"));
}

TEST(HtmlReport, AStreamedRunThatKeepsOnlyTheReportsSignalsReportsTheSame) {
    const std::string whole = printer_report(false), kept = printer_report(true);
    EXPECT_NE(whole.find("id=\"toolpath\""), std::string::npos);
    EXPECT_NE(whole.find("id=\"temperatures\""), std::string::npos);
    EXPECT_TRUE(whole == kept) << whole.size() << " bytes against " << kept.size();
}

}  // namespace
}  // namespace avrbench
