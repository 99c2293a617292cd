// Replaying one input on a fuzz target, and shrinking a reproducer while it
// keeps its root cause.
#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace avrbench::fuzz_campaign {

// How a target runs one input: libFuzzer's needs -runs=1, AFL++'s runs its
// argument once when no fork server is listening.
struct Target {
    std::string path;
    bool libfuzzer = true;
};

// The finding an input gives when the target runs it once ("" for none).
std::string replay(const Target& target, const std::vector<std::string>& env, const std::filesystem::path& input);

// Replays one root cause's minimisation may take (docs/FUZZING.md).
constexpr int kMinimizeReplays = 150;

// Shrinks `bytes` while the target still reports the same root cause:
// whole lines first, then single bytes (a greedy pass each; every try is a
// replay, so the tries are bounded, and so is the wall time: none after
// `deadline`).
std::string minimize(const Target& target, const std::vector<std::string>& env, const std::filesystem::path& scratch,
                     std::string bytes, const std::string& cause,
                     std::optional<std::chrono::steady_clock::time_point> deadline);

}  // namespace avrbench::fuzz_campaign
