#include "trace/GtkwWriter.hpp"

#include "core/OutputFile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "trace/ScopeGroups.hpp"

#ifndef AVRBENCH_VERSION
#define AVRBENCH_VERSION "dev"
#endif

namespace avrbench {

namespace {

// gtkwave's names for VCD variables: "scope.name", plus "[msb:0]" for vectors
// declared without a range, which is how VcdWriter declares buses.
std::string gtkwave_name(const SignalInfo& info) {
    std::string name = info.scope + "." + info.name;
    if (info.kind == SignalKind::Bus && info.width > 1) name += "[" + std::to_string(info.width - 1) + ":0]";
    return name;
}

}  // namespace

std::string format_gtkw(const Timeline& timeline, const std::string& dump_path, const std::string& save_file_name,
                        const GtkwOptions& options) {
    for (const std::string* name : {&dump_path, &save_file_name})
        if (name->find_first_of("\"\r\n") != std::string::npos)
            throw std::invalid_argument("gtkw save file: '" + *name +
                                        "' contains a quote or line break, which the format cannot hold");
    std::string text;
    text += "[*] avrbench " AVRBENCH_VERSION " save file: one group per scope\n";
    text += "[dumpfile] \"" + dump_path + "\"\n";
    if (!save_file_name.empty()) text += "[savefile] \"" + save_file_name + "\"\n";
    text += "[timestart] 0\n";
    if (options.fit_end_time > 0 && options.fit_width_pixels > 0) {
        // "100ps" -> 100: gtkwave counts time in the unit (ps), not in steps of 100 ps.
        const double multiplier = std::max(1.0, std::atof(options.fit_timescale.c_str()));
        constexpr double kPixelsPerUnitAtZoom0 = 192.0;
        const double units_per_pixel =
            static_cast<double>(options.fit_end_time) * multiplier / options.fit_width_pixels;
        const double zoom = -std::log2(units_per_pixel * kPixelsPerUnitAtZoom0);
        char line[64];
        std::snprintf(line, sizeof line, "*%.6f 0\n", zoom);
        text += line;
    }

    const auto& infos = timeline.signals();
    const std::vector<ScopeGroup> groups = group_by_scope(timeline);
    // Opens the scopes in gtkwave's signal tree too, so their signals are one click away.
    for (const ScopeGroup& group : groups) text += "[treeopen] " + group.scope + ".\n";

    const char* const group_begin = options.groups_closed ? "@c00200\n-" : "@800200\n-";
    for (const ScopeGroup& group : groups) {
        text += group_begin + group.scope + "\n";
        for (const SignalId id : group.signals) {
            const SignalInfo& info = infos[id];
            switch (info.kind) {
            case SignalKind::Wire: text += "@28\n"; break;
            case SignalKind::Bus: text += info.width > 1 ? "@22\n" : "@28\n"; break;
            case SignalKind::Real: text += "@8028\n"; break;
            }
            text += gtkwave_name(info) + "\n";
            if (info.kind == SignalKind::Real)
                for (unsigned row = 0; row < options.analog_extra_rows; ++row) text += "@20000\n-\n";
        }
        text += "@1000200\n-" + group.scope + "\n";
    }
    return text;
}

void write_gtkw(const Timeline& timeline, const std::string& gtkw_path, const std::string& dump_path,
                const GtkwOptions& options) {
    const std::string text =
        format_gtkw(timeline, dump_path, std::filesystem::path(gtkw_path).filename().string(), options);
    write_output_file(gtkw_path, text, "gtkwave save file");
}

}  // namespace avrbench
