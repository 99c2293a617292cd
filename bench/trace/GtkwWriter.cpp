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
// declared without a range, which is how VcdWriter declares buses. A bus
// written as bits is one trace made of its bits: "#{scope.name[msb:0]}"
// followed by "scope.name[msb]" ... "scope.name[0]", gtkwave's concatenation.
std::string gtkwave_name(const SignalInfo& info, VcdBuses buses) {
    const std::string name = info.scope + "." + info.name;
    if (info.kind != SignalKind::Bus || info.width <= 1) return name;
    const std::string range = "[" + std::to_string(info.width - 1) + ":0]";
    if (buses == VcdBuses::Vector) return name + range;
    std::string joined = "#{" + name + range + "}";
    for (unsigned bit = info.width; bit-- > 0;) joined += " " + name + "[" + std::to_string(bit) + "]";
    return joined;
}

// gtkwave's trace flags (its TR_* bits): 0x20 right-justify, 0x02 hex,
// 0x800 ASCII, 0x8000 analog interpolated, 0x20000 real.
std::string trace_flags(const SignalInfo& info) {
    switch (info.kind) {
    case SignalKind::Wire: return "@28\n";
    case SignalKind::Bus:
        if (info.characters && info.width == 8) return "@820\n";
        return info.width > 1 ? "@22\n" : "@28\n";
    case SignalKind::Real: return "@8028\n";
    }
    return "@28\n";
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
    if (options.window_width > 0 && options.window_height > 0)
        text += "[size] " + std::to_string(options.window_width) + " " + std::to_string(options.window_height) + "\n";
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

    const char* const open_group = options.groups_closed ? "@c00200\n-" : "@800200\n-";
    const char* const closed_group = "@c00200\n-";
    auto is_background = [&options](const std::string& scope) {
        return std::find(options.background_scopes.begin(), options.background_scopes.end(), scope) !=
               options.background_scopes.end();
    };
    // `which`: 0 every signal, 1 only the non-pins (buses, reals), 2 only the pins (1-bit wires).
    auto write_group = [&](const ScopeGroup& group, const char* begin, int which, const std::string& title) {
        bool any = false;
        for (const SignalId id : group.signals) any = any || which == 0 || (infos[id].kind == SignalKind::Wire) == (which == 2);
        if (!any) return;
        text += begin + title + "\n";
        for (const SignalId id : group.signals) {
            const SignalInfo& info = infos[id];
            if (which != 0 && (info.kind == SignalKind::Wire) != (which == 2)) continue;
            text += trace_flags(info);
            text += gtkwave_name(info, options.buses) + "\n";
            if (info.kind == SignalKind::Real)
                for (unsigned row = 0; row < options.analog_extra_rows; ++row) text += "@20000\n-\n";
        }
        text += "@1000200\n-" + title + "\n";
    };
    // Aliases (net and label names: what the board file calls the wires)
    // first, as groups of their own shown like their targets; then the
    // parts; the MCUs' raw pins last, collapsed.
    std::vector<std::string> alias_scopes;
    for (const auto& a : timeline.aliases()) {
        if (std::find(alias_scopes.begin(), alias_scopes.end(), a.scope) == alias_scopes.end()) alias_scopes.push_back(a.scope);
    }
    for (const auto& scope : alias_scopes) {
        if (std::any_of(groups.begin(), groups.end(), [&](const ScopeGroup& g) { return g.scope == scope; })) continue;
        text += open_group + scope + "\n";
        for (const auto& a : timeline.aliases()) {
            if (a.scope != scope) continue;
            SignalInfo shown = infos[a.target];
            shown.scope = a.scope;
            shown.name = a.name;
            text += trace_flags(shown) + gtkwave_name(shown, options.buses) + "\n";
        }
        text += "@1000200\n-" + scope + "\n";
    }
    // A background scope's bytes (its USARTs' and TWI's) stay in view; only
    // its pins go to the collapsed group at the end.
    for (const ScopeGroup& group : groups) {
        if (!is_background(group.scope)) {
            write_group(group, open_group, 0, group.scope);
        } else {
            write_group(group, open_group, 1, group.scope);
        }
    }
    for (const ScopeGroup& group : groups)
        if (is_background(group.scope)) write_group(group, closed_group, 2, group.scope + " pins");
    return text;
}

void write_gtkw(const Timeline& timeline, const std::string& gtkw_path, const std::string& dump_path,
                const GtkwOptions& options) {
    const std::string text =
        format_gtkw(timeline, dump_path, std::filesystem::path(gtkw_path).filename().string(), options);
    write_output_file(gtkw_path, text, "gtkwave save file");
}

}  // namespace avrbench
