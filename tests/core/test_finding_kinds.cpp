// Finding kinds are an open set: whoever finds a kind declares it in its own
// source file, and the registry knows it without any list (core/Finding.hpp).
#include <gtest/gtest.h>

#include <stdexcept>

#include "core/Finding.hpp"
#include "mcu/Mcu.hpp"

namespace avrbench {
namespace {

TEST(FindingKinds, APartsKindIsKnownWithoutAnyReferenceToThePart) {
    // This file includes no part header: "motor-stall" is registered by
    // parts/HybridStepper.cpp alone, kept by the whole-archive link.
    const auto stall = FindingKind::find("motor-stall");
    ASSERT_TRUE(stall.has_value());
    EXPECT_EQ(stall->severity(), Severity::Warning);
    EXPECT_FALSE(FindingKind::find("no-such-kind").has_value());
}

TEST(FindingKinds, TheFirmwaresOwnFailuresAreErrors) {
    // docs/CLI.md: crashes and resets fail every run; part findings only under --strict.
    EXPECT_EQ(Mcu::kStackOverflow.severity(), Severity::Error);
    EXPECT_EQ(Mcu::kStackOverflow.name(), "stack-overflow");
    EXPECT_EQ(FindingKind::find("stack-overflow"), Mcu::kStackOverflow);
}

TEST(FindingKinds, ADeclarationIsOneKindPerName) {
    const FindingKind a = FindingKind::declare("test-only-kind", "declared by this test", Severity::Warning);
    const FindingKind b = FindingKind::declare("test-only-kind", "declared again", Severity::Warning);
    EXPECT_EQ(a, b);
    EXPECT_THROW(FindingKind::declare("test-only-kind", "other severity", Severity::Error), std::logic_error);
}

TEST(FindingKinds, AllIsSortedByName) {
    const auto all = FindingKind::all();
    ASSERT_GE(all.size(), 21u);  // 7 MCU + 2 net + 12 part and host kinds (docs/CLI.md)
    for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LT(all[i - 1].name(), all[i].name());
}

}  // namespace
}  // namespace avrbench
