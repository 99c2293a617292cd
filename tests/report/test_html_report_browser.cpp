// The report renders in a real browser: Debian's chromium, headless, takes a
// screenshot (decoded with libpng: right size, not blank, every plot colour
// drawn) and dumps the DOM after parsing (every plot element there, with
// points). chromium comes from ci/setup; a missing chromium fails the test.
#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "parts/Part.hpp"
#include "report/HtmlReportTestSupport.hpp"
#include "support/Paths.hpp"
#include "run/Bench.hpp"
#include "trace/HtmlReport.hpp"
#include "trace/TraceTestSupport.hpp"

namespace avrbench {
namespace {

using namespace report_test;
using trace_test::quoted;
using trace_test::read_text;
using trace_test::ScratchDir;

constexpr int kWindowWidth = 1280;
constexpr int kWindowHeight = 5200;  // tall enough for every section of the demo report

struct Rgb {
    int r, g, b;
};

struct Image {
    unsigned width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
    Rgb at(unsigned x, unsigned y) const {
        const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
};

// Decodes a PNG with libpng's simplified API; empty image and a failure on error.
Image read_png(const std::string& path) {
    Image image;
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (png_image_begin_read_from_file(&png, path.c_str()) == 0) {
        ADD_FAILURE() << "libpng cannot read " << path << ": " << png.message;
        return image;
    }
    png.format = PNG_FORMAT_RGB;
    image.width = png.width;
    image.height = png.height;
    image.rgb.resize(static_cast<std::size_t>(png.width) * png.height * 3);
    if (png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr) == 0) {
        ADD_FAILURE() << "libpng cannot decode " << path << ": " << png.message;
        png_image_free(&png);
        return {};
    }
    return image;
}

bool near(Rgb a, Rgb b, int tolerance) {
    return std::abs(a.r - b.r) <= tolerance && std::abs(a.g - b.g) <= tolerance && std::abs(a.b - b.b) <= tolerance;
}

std::size_t pixels_near(const Image& image, Rgb colour, int tolerance) {
    std::size_t n = 0;
    for (unsigned y = 0; y < image.height; ++y)
        for (unsigned x = 0; x < image.width; ++x)
            if (near(image.at(x, y), colour, tolerance)) ++n;
    return n;
}

// Runs chromium headless with a fresh profile (and HOME) under `scratch`;
// `what` is "--screenshot=FILE" or "--dump-dom". Returns the exit status;
// stdout goes to `out`, stderr to `log`. `timeout` bounds it: the suite never hangs.
int run_chromium(const std::string& chromium, const ScratchDir& scratch, const std::string& name,
                 const std::string& what, const std::string& url, const std::string& out, const std::string& log) {
    const std::filesystem::path home = scratch.path() / (name + "-home");
    const std::filesystem::path profile = scratch.path() / (name + "-profile");
    std::filesystem::create_directories(home);
    std::filesystem::create_directories(profile);
    const std::string command =
        "cd " + quoted(scratch.path().string()) + " && HOME=" + quoted(home.string()) + " XDG_CONFIG_HOME=" +
        quoted(home.string()) + " XDG_CACHE_HOME=" + quoted(home.string()) + " timeout -k 10 90 " + quoted(chromium) +
        " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking"
        " --disable-component-update --disable-sync --disable-extensions --disable-default-apps"
        " --hide-scrollbars --force-device-scale-factor=1 --user-data-dir=" +
        quoted(profile.string()) + " --window-size=" + std::to_string(kWindowWidth) + "," +
        std::to_string(kWindowHeight) + " " + what + " " + quoted(url) + " >" + quoted(out) + " 2>" + quoted(log) +
        " </dev/null";
    const int status = std::system(command.c_str());
    std::error_code ignored;
    std::filesystem::remove_all(profile, ignored);
    std::filesystem::remove_all(home, ignored);
    if (status == -1 || !WIFEXITED(status)) return -1;
    return WEXITSTATUS(status);
}

TEST(HtmlReport, RendersInHeadlessChromium) {
    const std::string chromium = trace_test::find_program("chromium");
    ASSERT_FALSE(chromium.empty()) << "chromium not found on PATH: run ci/setup (it installs Debian's chromium)";
    ASSERT_FALSE(trace_test::find_program("timeout").empty()) << "timeout (coreutils) not found";

    ScratchDir dir;
    DemoRun run = square_run(true);
    add_everything(run);
    const std::string html_path = dir.file("report.html");
    write_html_report(run.report, html_path);
    const std::string url = "file://" + html_path;

    // --- the DOM after parsing and layout
    const std::string dom_path = dir.file("dom.html"), dom_log = dir.file("dom.log");
    const int dom_status = run_chromium(chromium, dir, "dom", "--dump-dom", url, dom_path, dom_log);
    ASSERT_EQ(dom_status, 0) << "chromium --dump-dom failed (124 = timed out):\n" << read_text(dom_log);
    const std::string dom = read_text(dom_path);
    ASSERT_GT(dom.size(), 1000u) << read_text(dom_log);
    const std::vector<std::pair<std::string, std::string>> plots = {
        {"toolpath", "path"},           {"toolpath-xz", "path"},         {"toolpath-yz", "path"},
        {"velocity-x", "x velocity [mm/s]"}, {"velocity-y", "y velocity [mm/s]"}, {"velocity-z", "z velocity [mm/s]"},
        {"temperatures", "hotend block"},     {"heater-duty", "hotend heater"}, {"servos", "servo0"},
        {"comparison-mcu-PD2", "golden"}, {"comparison-mcu-PD2", "actual"},
        {"comparison-mcu-PD2-detail", "actual"}, {"comparison-mcu-PD2-overview", "golden"}};
    for (const auto& [id, series] : plots) {
        const std::string svg = element(dom, "svg", id);
        ASSERT_NE(svg, "") << id << " missing from the DOM";
        EXPECT_EQ(svg.rfind("<svg class=\"plot", 0), 0u) << id;
        EXPECT_GE(polyline(svg, series).size(), 2u) << id << " / " << series << " has no points in the DOM";
    }
    EXPECT_NE(element(dom, "table", "findings"), "");
    EXPECT_NE(element(dom, "pre", "transcript"), "");
    EXPECT_NE(dom.find("<line class=\"divergence\""), std::string::npos);

    // --- the screenshot
    const std::string png_path = dir.file("report.png"), png_log = dir.file("png.log");
    const int png_status =
        run_chromium(chromium, dir, "png", "--screenshot=" + quoted(png_path), url, dir.file("png.out"), png_log);
    ASSERT_EQ(png_status, 0) << "chromium --screenshot failed (124 = timed out):\n" << read_text(png_log);
    ASSERT_TRUE(std::filesystem::exists(png_path)) << read_text(png_log);
    const Image image = read_png(png_path);
    ASSERT_EQ(image.width, static_cast<unsigned>(kWindowWidth));
    ASSERT_EQ(image.height, static_cast<unsigned>(kWindowHeight));

    // Not blank: much of the page differs from its background, with many colours.
    const Rgb background{0xee, 0xf0, 0xf3};
    const std::size_t total = static_cast<std::size_t>(image.width) * image.height;
    const std::size_t not_background = total - pixels_near(image, background, 2);
    EXPECT_GT(not_background, total / 5) << "screenshot looks blank";
    // Every plot colour was drawn: toolpath/x velocity blue, y red, z green,
    // golden light blue, actual near-black, divergence red, start green.
    const std::vector<std::pair<const char*, Rgb>> colours = {{"toolpath blue #1f77b4", {0x1f, 0x77, 0xb4}},
                                                              {"red #d62728", {0xd6, 0x27, 0x28}},
                                                              {"green #2ca02c", {0x2c, 0xa0, 0x2c}},
                                                              {"golden #8fbce6", {0x8f, 0xbc, 0xe6}},
                                                              {"header #1d2330", {0x1d, 0x23, 0x30}}};
    for (const auto& [name, colour] : colours)
        EXPECT_GT(pixels_near(image, colour, 12), 400u) << name << " hardly drawn in " << png_path;

    // Each plot area (a #fcfcfd rectangle framed in #aab1bc, drawn crisp)
    // found in the screenshot has ink in it: series, markers, labels.
    struct Run {
        unsigned x0, x1, y;
    };
    std::vector<Run> edges;  // horizontal frame edges, 150 px or longer
    const Rgb frame{0xaa, 0xb1, 0xbc}, area{0xfc, 0xfc, 0xfd}, grid{0xe3, 0xe6, 0xeb}, zero{0x9a, 0xa2, 0xad};
    for (unsigned y = 0; y < image.height; ++y)
        for (unsigned x = 0; x < image.width;) {
            unsigned end = x;
            while (end < image.width && near(image.at(end, y), frame, 6)) ++end;
            if (end - x >= 150) edges.push_back({x, end - 1, y});
            x = end == x ? x + 1 : end;
        }
    std::vector<std::pair<Run, Run>> areas;  // top and bottom edge
    std::vector<bool> used(edges.size(), false);
    for (std::size_t i = 0; i < edges.size(); ++i) {
        if (used[i]) continue;
        for (std::size_t j = i + 1; j < edges.size(); ++j)
            if (!used[j] && edges[j].x0 == edges[i].x0 && edges[j].x1 == edges[i].x1 && edges[j].y > edges[i].y + 20) {
                used[i] = used[j] = true;
                areas.emplace_back(edges[i], edges[j]);
                break;
            }
    }
    EXPECT_EQ(areas.size(), plots.size() - 1) << "plot areas found in the screenshot (one per svg)";
    for (const auto& [top, bottom] : areas) {
        std::size_t ink = 0;
        for (unsigned y = top.y + 1; y < bottom.y; ++y)
            for (unsigned x = top.x0 + 1; x < top.x1; ++x) {
                const Rgb c = image.at(x, y);
                if (!near(c, area, 3) && !near(c, grid, 3) && !near(c, zero, 3) && !near(c, frame, 3)) ++ink;
            }
        EXPECT_GT(ink, 250u) << "plot area " << top.x0 << "," << top.y << " to " << top.x1 << "," << bottom.y
                             << " looks empty";
    }

    // Blue is drawn by the toolpath views, the x velocity, the temperature and
    // the servo plots: together they spread across the plot width and down the page.
    unsigned min_x = image.width, max_x = 0, min_y = image.height, max_y = 0;
    for (unsigned y = 0; y < image.height; ++y)
        for (unsigned x = 0; x < image.width; ++x)
            if (near(image.at(x, y), {0x1f, 0x77, 0xb4}, 12)) {
                min_x = std::min(min_x, x), max_x = std::max(max_x, x);
                min_y = std::min(min_y, y), max_y = std::max(max_y, y);
            }
    EXPECT_GT(max_x - min_x, 700u) << "blue should span the time plots' width";
    EXPECT_GT(max_y - min_y, 1500u) << "blue should reach from the toolpath down to the servo plot";

    if (const char* keep = std::getenv("AVRBENCH_KEEP_REPORT")) {
        std::filesystem::copy_file(png_path, std::string(keep) + ".png", std::filesystem::copy_options::overwrite_existing);
        std::filesystem::copy_file(html_path, std::string(keep) + ".html",
                                   std::filesystem::copy_options::overwrite_existing);
    }
}

// Reports of real bench runs, read back from the DOM chromium built: what
// a person sees on the page, with numbers checked against hand calculations.
std::string rendered_dom(const ScratchDir& dir, const RunReport& report, const std::string& name) {
    const std::string chromium = trace_test::find_program("chromium");
    if (chromium.empty()) {
        ADD_FAILURE() << "chromium not found on PATH: run ci/setup";
        return "";
    }
    const std::string html_path = dir.file(name + ".html");
    write_html_report(report, html_path);
    const std::string dom_path = dir.file(name + ".dom.html"), log = dir.file(name + ".log");
    EXPECT_EQ(run_chromium(chromium, dir, name, "--dump-dom", "file://" + html_path, dom_path, log), 0) << read_text(log);
    return read_text(dom_path);
}

TEST(HtmlReport, ConstantStepRateIsDrawnAsAConstantVelocity) {
    ScratchDir dir;
    Bench bench(test::source_path("bench/boards/arduino-uno-cnc-shield-v3.yaml"), test::firmware("stepdir_test"));
    UartHostOptions generic = default_host_options(bench.serial_port());
    generic.family = FirmwareFamily::Generic;  // our test firmware prints no grbl welcome
    bench.host("", generic);
    bench.trace_board();
    bench.host().add_lines("E1\nX1600\n");
    ASSERT_EQ(bench.run_until_idle(2.0), IdleResult::Idle);
    const std::string dom = rendered_dom(dir, bench.make_report("velocity"), "velocity");
    const std::string svg = element(dom, "svg", "velocity-x");
    ASSERT_NE(svg, "");
    const PlotMapping map(svg);
    const Points v = polyline(svg, "x velocity [mm/s]");
    ASSERT_GE(v.size(), 4u);
    // stepdir_test steps every 16 * (5 + 45) = 800 cycles = 50 us (20 kHz)
    // with DIR high, which this board (grbl's convention) counts as -; the
    // x axis has 250 steps/mm: 20000 / 250 = 80 mm/s, for 1600 steps = 80 ms.
    // Every point while moving is -80 mm/s, none between.
    double fastest = 0;
    std::size_t moving = 0;
    for (const auto& [px, py] : v) {
        const double mm_s = map.data_y(py);
        fastest = std::min(fastest, mm_s);
        if (mm_s < -1) {
            ++moving;
            EXPECT_NEAR(mm_s, -80.0, 0.8) << "at " << map.data_x(px) << " s";
        }
    }
    EXPECT_NEAR(fastest, -80.0, 0.8);
    EXPECT_GE(moving, 2u);
}

TEST(HtmlReport, ThermalRunShowsSensorTargetDutyInsideTheFrameAndTheFault) {
    ScratchDir dir;
    Bench bench(test::source_path("bench/boards/ramps-1.4.yaml"), test::firmware("thermal_pid"));
    UartHostOptions generic = default_host_options(bench.serial_port());
    generic.family = FirmwareFamily::Generic;  // thermal_pid prints no Marlin welcome
    bench.host("", generic);
    bench.trace_board();
    // thermal_pid reads no serial input: the line stays unanswered, but what
    // the host sent sets the target drawn in the report.
    bench.host().add_line("M104 S200");
    bench.board().part("hotend_heater").inject_fault("disconnected", 16000000ull * 6);  // at 6 s
    bench.run_for(10.0);
    const RunReport report = bench.make_report("thermal");
    const std::string dom = rendered_dom(dir, report, "thermal");
    const std::string svg = element(dom, "svg", "temperatures");
    ASSERT_NE(svg, "");
    const PlotMapping map(svg);
    EXPECT_GE(polyline(svg, "hotend block").size(), 2u);
    EXPECT_GE(polyline(svg, "hotend sensor").size(), 2u);
    const Points target = polyline(svg, "hotend target");
    ASSERT_GE(target.size(), 2u);
    EXPECT_NEAR(map.data_y(target.back().second), 200.0, 0.5);  // M104 S200
    // The fault marker at 6 s, on the temperature plot and the duty plot.
    const std::size_t marker = svg.find("<g class=\"fault-marker\"");
    ASSERT_NE(marker, std::string::npos) << svg.substr(0, 400);
    EXPECT_NEAR(number_attribute(svg.substr(marker), "data-t"), 6.0, 1e-3);
    EXPECT_NE(svg.find("fault hotend_heater: disconnected"), std::string::npos);
    const std::string duty = element(dom, "svg", "heater-duty");
    ASSERT_NE(duty, "");
    const PlotMapping dmap(duty);
    const Points d = polyline(duty, "hotend heater");
    ASSERT_GE(d.size(), 2u);
    // The PID firmware starts at full power: 100 % drawn, and inside the frame.
    double highest_px = 1e9;
    for (const auto& p : d) highest_px = std::min(highest_px, p.second);
    EXPECT_NEAR(dmap.data_y(highest_px), 100.0, 0.5);
    EXPECT_GT(highest_px, dmap.top + 1.0);
    EXPECT_NE(duty.find("fault-marker"), std::string::npos);
}

}  // namespace
}  // namespace avrbench
