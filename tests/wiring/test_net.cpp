// Net resolution (wiring/Drive.hpp, wiring/Net.hpp) against the logic-input
// thresholds of the datasheets' DC tables: V_IL max 0.3 VCC, V_IH min 0.6 VCC.
#include <gtest/gtest.h>

#include <vector>

#include "wiring/Net.hpp"

namespace avrbench {
namespace {

Resolution of(std::vector<Drive> drives) { return resolve(drives); }

TEST(NetResolve, StrongDriversWinAndDisagreeingOnesContend) {
    EXPECT_EQ(of({}).state, NetState::Floating);
    EXPECT_FALSE(of({}).level);
    EXPECT_EQ(of({Drive::strong(true)}).state, NetState::Driven);
    EXPECT_TRUE(of({Drive::strong(true)}).level);
    // A strong low against a pull-up: low (the pull-up only sets an open net's level).
    const Resolution pulled_down = of({Drive::strong(false), Drive::weak(true, 35e3)});
    EXPECT_EQ(pulled_down.state, NetState::Driven);
    EXPECT_FALSE(pulled_down.level);
    const Resolution fight = of({Drive::strong(true), Drive::strong(false)});
    EXPECT_EQ(fight.state, NetState::Contention);
    EXPECT_FALSE(fight.level);  // the bench reads 0 (docs/ELECTRICAL.md)
}

TEST(NetResolve, PullResistorsFormADividerReadAgainstTheThresholds) {
    // A pull-up alone: VCC, a valid 1.
    const Resolution up = of({Drive::weak(true, 10e3)});
    EXPECT_EQ(up.state, NetState::Driven);
    EXPECT_TRUE(up.level);
    EXPECT_DOUBLE_EQ(up.volts_fraction, 1.0);
    // 35 k up, 10 k down: 10 / 45 = 0.222 VCC < 0.3 VCC: a valid 0.
    const Resolution low = of({Drive::weak(true, 35e3), Drive::weak(false, 10e3)});
    EXPECT_EQ(low.state, NetState::Driven);
    EXPECT_FALSE(low.level);
    EXPECT_NEAR(low.volts_fraction, 10.0 / 45.0, 1e-12);
    // 10 k up, 35 k down: 35 / 45 = 0.778 VCC > 0.6 VCC: a valid 1.
    const Resolution high = of({Drive::weak(true, 10e3), Drive::weak(false, 35e3)});
    EXPECT_EQ(high.state, NetState::Driven);
    EXPECT_TRUE(high.level);
    // Equal resistors: 0.5 VCC, between V_IL and V_IH: undefined, floating.
    const Resolution middle = of({Drive::weak(true, 10e3), Drive::weak(false, 10e3)});
    EXPECT_EQ(middle.state, NetState::Floating);
    EXPECT_NEAR(middle.volts_fraction, 0.5, 1e-12);
}

// A terminal that drives what it is told and keeps what it receives.
class TestTerminal final : public Terminal {
public:
    std::string label() const override { return "t"; }
    TerminalRole role() const override { return TerminalRole::Output; }
    Drive drive_state() const override { return drive_; }
    void receive(const Resolution& r) override { received.push_back(r); }
    void set(Drive d) {
        drive_ = d;
        drive_changed();
    }
    std::vector<Resolution> received;

private:
    Drive drive_;
};

TEST(Net, DeliversTheFirstResolutionAndThenOnlyChanges) {
    Net net("n");
    TestTerminal a, b;
    net.connect(a);
    net.connect(b);
    a.set(Drive::weak(true, 10e3));  // before settle(): nothing is delivered yet
    EXPECT_TRUE(b.received.empty());
    net.settle();
    ASSERT_EQ(b.received.size(), 1u);
    EXPECT_TRUE(b.received.back().level);
    a.set(Drive::weak(true, 20e3));  // still a valid 1: no new delivery
    EXPECT_EQ(b.received.size(), 1u);
    b.set(Drive::strong(false));     // the other terminal pulls it low: delivered to both
    ASSERT_EQ(a.received.size(), 2u);
    EXPECT_FALSE(a.received.back().level);
    EXPECT_EQ(net.resolution().state, NetState::Driven);
    EXPECT_FALSE(net.level());
}

}  // namespace
}  // namespace avrbench
