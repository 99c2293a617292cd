#include "run/LiveStatus.hpp"

#include "core/Format.hpp"
#include "run/Bench.hpp"
#include "stimulus/UartHost.hpp"

namespace avrbench {

namespace {

// A part's signal or readout by name, if it has it.
std::optional<double> value_of(const Part& part, const std::string& name) {
    if (const auto i = part.signal_index(name)) return part.signal_value(*i);
    if (const auto* r = part.find_readout(name)) return r->value();
    return std::nullopt;
}

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

}  // namespace

LiveStatus live_status(Bench& bench, const UartHost* job_host, double wall_s) {
    const double now_s = bench.now_seconds();
    std::string line = format_text("status %.3f s (wall %.1f s):", now_s, wall_s);
    std::string axes, temperatures;
    for (Part* part : bench.board().parts()) {
        const std::string type(part->type());
        if (type == "linear_axis" || type == "rotary_axis") {
            const bool linear = type == "linear_axis";
            const auto at = value_of(*part, linear ? "position_mm" : "angle_deg");
            const auto steps = value_of(*part, "steps");
            if (!at) continue;
            line += format_text(" %s %.3f %s (%.0f steps),", part->name().c_str(), *at, linear ? "mm" : "deg", steps.value_or(0));
            axes += format_text("%s%s: {\"%s\": %.6f, \"steps\": %.0f}", axes.empty() ? "" : ", ", json_string(part->name()).c_str(),
                                linear ? "position_mm" : "angle_deg", *at, steps.value_or(0));
        } else if (type == "thermal_plant") {
            const auto t = value_of(*part, "block_degC");
            if (!t) continue;
            line += format_text(" %s %.1f degC,", part->name().c_str(), *t);
            temperatures += format_text("%s%s: %.3f", temperatures.empty() ? "" : ", ", json_string(part->name()).c_str(), *t);
        }
    }
    std::string job = "null";
    if (const UartHost* host = job_host) {
        line += format_text(" job %zu of %zu lines answered,", host->lines_acknowledged(), host->lines().size());
        job = format_text("{\"lines\": %zu, \"answered\": %zu}", host->lines().size(), host->lines_acknowledged());
    }
    const auto findings = bench.findings();
    line += format_text(" findings %zu", findings.size());
    std::string kinds;
    for (const auto& f : findings) kinds += (kinds.empty() ? "" : ", ") + json_string(std::string(f.kind.name()));
    const std::string json = format_text(
        "{\"simulated_s\": %.6f, \"wall_s\": %.3f, \"axes\": {%s}, \"temperatures_degC\": {%s}, \"job\": %s, "
        "\"findings\": %zu, \"finding_kinds\": [%s]}\n",
        now_s, wall_s, axes.c_str(), temperatures.c_str(), job.c_str(), findings.size(), kinds.c_str());
    return {line, json};
}

}  // namespace avrbench
