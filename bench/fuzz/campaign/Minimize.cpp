#include "fuzz/campaign/Minimize.hpp"

#include <fstream>

#include "fuzz/FuzzFindings.hpp"
#include "fuzz/campaign/Processes.hpp"

namespace avrbench::fuzz_campaign {

namespace fs = std::filesystem;

std::string replay(const Target& target, const std::vector<std::string>& env, const fs::path& input) {
    const std::string log = input.string() + ".replay.txt";
    if (target.libfuzzer) {
        run_logged({target.path, "-runs=1", input.string()}, env, log);
    } else {
        run_logged({target.path, input.string()}, env, log);
    }
    const std::string output = slurp(log);
    fs::remove(log);
    const auto at = output.find("avrbench fuzz: FINDING");
    return at == std::string::npos ? "" : output.substr(at, output.find('\n', at) - at);
}



std::string minimize(const Target& target, const std::vector<std::string>& env, const fs::path& scratch,
                     std::string bytes, const std::string& cause,
                     std::optional<std::chrono::steady_clock::time_point> deadline) {
    int budget = kMinimizeReplays;
    const auto same = [&](const std::string& candidate) {
        if (budget-- <= 0) return false;
        if (deadline && std::chrono::steady_clock::now() >= *deadline) {
            budget = 0;
            return false;
        }
        std::ofstream(scratch, std::ios::binary) << candidate;
        const std::string found = replay(target, env, scratch);
        return !found.empty() && finding_root_cause(found) == cause;
    };
    for (bool shrunk = true; shrunk && budget > 0;) {
        shrunk = false;
        for (std::size_t start = 0; start < bytes.size() && budget > 0;) {
            std::size_t end = bytes.find('\n', start);
            end = end == std::string::npos ? bytes.size() : end + 1;
            const std::string candidate = bytes.substr(0, start) + bytes.substr(end);
            if (same(candidate)) {
                bytes = candidate;
                shrunk = true;
            } else {
                start = end;
            }
        }
    }
    for (std::size_t i = 0; i < bytes.size() && budget > 0;) {
        const std::string candidate = bytes.substr(0, i) + bytes.substr(i + 1);
        if (same(candidate)) {
            bytes = candidate;
        } else {
            ++i;
        }
    }
    fs::remove(scratch);
    return bytes;
}

}  // namespace avrbench::fuzz_campaign
