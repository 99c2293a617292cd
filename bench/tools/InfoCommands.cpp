// `avrbench boards`, `avrbench findings` and `avrbench cam`: what the build
// knows, and seed 002's CAM on its own.
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "boards/BoardFile.hpp"
#include "cam/Chain.hpp"
#include "cam/DxfReader.hpp"
#include "core/Errors.hpp"
#include "core/Finding.hpp"
#include "core/InputFile.hpp"
#include "core/OutputFile.hpp"
#include "core/Units.hpp"
#include "tools/Commands.hpp"
#include "trace/WaveformFiles.hpp"

namespace avrbench {
namespace {

// `avrbench findings`: every finding kind the linked layers and parts declare.
int findings_command() {
    std::size_t width = 0;
    for (const FindingKind kind : FindingKind::all()) width = std::max(width, kind.name().size());
    std::printf("Finding kinds (error: fails every run; warning: fails under --strict)\n");
    for (const FindingKind kind : FindingKind::all()) {
        std::printf("  %-*s  %-7s  %s\n", static_cast<int>(width), kind.name().c_str(), to_string(kind.severity()),
                    kind.meaning().c_str());
    }
    return kExitOk;
}

// `avrbench boards`: the standard boards a bare name selects, with their descriptions.
int boards_command() {
    const std::vector<StandardBoard> boards = list_standard_boards();
    if (boards.empty()) {
        throw BadInput("no standard boards found (looked in: $AVRBENCH_BOARDS_DIR, <prefix>/share/avrbench/boards, the source tree)");
    }
    std::size_t width = 0;
    for (const auto& b : boards) width = std::max(width, b.name.size());
    std::printf("Standard boards (run --board NAME, or `board: NAME` in a scenario); files in %s\n",
                std::filesystem::path(boards.front().path).parent_path().string().c_str());
    for (const auto& b : boards) {
        std::printf("  %-*s  %s\n", static_cast<int>(width), escaped(b.name).c_str(),
                    escaped(b.error.empty() ? b.description : "(does not load: " + b.error + ")").c_str());
    }
    return kExitOk;
}

struct CamArgs {
    std::string dxf;
    std::string out;            // .nc file ("" = beside the DXF)
    std::string tolerance = "0.01mm";
    std::string feed = "120";   // mm/min: as run --dxf, the plotter tests' 2 mm/s
};

// DXF -> aligned segments -> G-code (seed 002's CAD2G, docs/CNC.md).
int cam_command(const CamArgs& args) {
    const std::string out = args.out.empty() ? with_extension(args.dxf, ".nc") : args.out;
    RunFiles files;
    files.input(args.dxf, "the drawing");
    files.output(out, args.out.empty() ? "the G-code (the DXF's name with .nc)" : "-o");
    files.check();
    DxfReadResult read = read_dxf(args.dxf);
    const double tolerance_mm = parse_quantity(args.tolerance, Dimension::Length, "--tolerance") * 1e3;
    if (!(tolerance_mm >= 0 && tolerance_mm <= 10)) throw BadInput("--tolerance: must be from 0 to 10 mm");
    const double feed = parse_quantity(args.feed, Dimension::Dimensionless, "--feed");
    if (!(feed > 0 && feed <= 1e5)) throw BadInput("--feed: mm/min above 0 and at most 100000");
    const GcodeProgram before = emit_gcode(read.drawing, tolerance_mm, feed);
    const ChainStats stats = align_segments(read.drawing, tolerance_mm);
    const GcodeProgram after = emit_gcode(read.drawing, tolerance_mm, feed);
    write_output_file(out, after.text, "-o");
    std::printf("avrbench cam: %s\n", args.dxf.c_str());
    std::printf("  entities   %zu (lines, arcs, circles); %u others skipped\n", read.drawing.segments.size(),
                read.skipped_entities);
    std::printf("  aligned    %u passes, tolerance %g mm%s\n", stats.revisions, tolerance_mm,
                stats.revisions >= 100 ? " (the thesis' cap: on a closed path its case 3 fires on every pass)" : "");
    std::printf("  commands   %u -> %u (rapids %u -> %u)\n", before.commands, after.commands, before.rapids, after.rapids);
    std::printf("  g-code     %s\n", out.c_str());
    return kExitOk;
}

}  // namespace

std::vector<Command> add_info_commands(CLI::App& app) {
    CLI::App* boards_cmd = app.add_subcommand("boards", "list the standard boards (names for --board and scenarios) with their descriptions");
    CLI::App* findings_cmd = app.add_subcommand("findings", "list the finding kinds with their severity and meaning");
    auto cam_args = std::make_shared<CamArgs>();
    CamArgs& cam = *cam_args;
    CLI::App* cam_cmd = app.add_subcommand("cam", "seed 002's CAM: a DXF drawing (lines, arcs, circles) to G-code");
    cam_cmd->add_option("dxf", cam.dxf, "the drawing, machine millimetres from home")->required();
    cam_cmd->add_option("-o,--output", cam.out, "the .nc file to write (default: beside the DXF)");
    cam_cmd->add_option("--tolerance", cam.tolerance, "endpoints closer than this are one point (default 0.01mm)");
    cam_cmd->add_option("--feed", cam.feed, "drawing feed in mm/min (default 120, as run --dxf)");

    return {{boards_cmd, [] { return boards_command(); }},
            {findings_cmd, [] { return findings_command(); }},
            {cam_cmd, [cam_args] { return cam_command(*cam_args); }}};
}

}  // namespace avrbench
