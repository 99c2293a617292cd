// The two engines of a firmware fuzz campaign: Debian's libFuzzer (one job
// in one process, or its fork mode) and AFL++ (a main and secondary
// instances on a shared sync folder).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "fuzz/campaign/FuzzCampaign.hpp"
#include "fuzz/campaign/Minimize.hpp"

namespace avrbench::fuzz_campaign {

// What a campaign leaves for the replays, whichever engine ran it.
struct Campaign {
    Target target;
    unsigned long executions = 0;
    unsigned long coverage_start = 0, coverage_end = 0;
    unsigned long wall_timeouts = 0;  // AFL++ only
    // libFuzzer only (each job says it at exit): inputs run, and those that
    // ended repeating themselves before their bound (AVRBENCH_FUZZ_STEADY).
    unsigned long inputs_counted = 0, ended_steady = 0;
    std::vector<std::filesystem::path> artifacts;  // inputs the engine kept as crashes
    std::string artifact_dir;
};

// "60 s" or "20000 executions (at most 300 s)".
std::string budget_text(const FuzzCampaignOptions& args, double seconds);

Campaign libfuzzer_campaign(const FuzzCampaignOptions& args, const std::vector<std::string>& env, const std::filesystem::path& out,
                            const std::filesystem::path& corpus, const std::filesystem::path& findings, double seconds,
                            const std::string& family);
Campaign afl_campaign(const FuzzCampaignOptions& args, const std::vector<std::string>& env, const std::filesystem::path& out,
                      const std::filesystem::path& corpus, double seconds, double bound_s, const std::string& family);

}  // namespace avrbench::fuzz_campaign
