// Removes a passed test's scratch directories (test::scratch_dir) when it
// ends: a run of the suite used to leave ~300 MB in /tmp (fuzz campaigns,
// copies of the fuzz target), and CI runs again and again on one machine.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "support/RunCommand.hpp"

namespace avrbench::test {
namespace {

class RemoveScratchOfPassedTests final : public ::testing::EmptyTestEventListener {
    void OnTestEnd(const ::testing::TestInfo& info) override {
        auto& dirs = scratch_dirs_of_this_test();
        const char* keep = std::getenv("AVRBENCH_KEEP_SCRATCH");
        if (info.result() != nullptr && info.result()->Passed() && (keep == nullptr || std::string(keep) != "1")) {
            for (const auto& dir : dirs) {
                std::error_code ignored;
                std::filesystem::remove_all(dir, ignored);
            }
        }
        dirs.clear();
    }
};

[[maybe_unused]] const bool registered = [] {
    ::testing::UnitTest::GetInstance()->listeners().Append(new RemoveScratchOfPassedTests);
    return true;
}();

}  // namespace
}  // namespace avrbench::test
