// The plant's maths (parts/ThermalNetwork): the exact solution against the
// closed form of one node, against an independent matrix exponential of the
// augmented system for several nodes, and the energy balance.
#include <gtest/gtest.h>

#include <cmath>
#include <unsupported/Eigen/MatrixFunctions>

#include "parts/ThermalNetwork.hpp"

namespace avrbench {
namespace {

TEST(ThermalNetwork, OneNodeFollowsTheClosedFormStepResponse) {
    // C = 16.7 J/K, g = 0.068 W/K (Marlin's MPC defaults), P = 40 W from 25 degC:
    // T(t) = 25 + P/g (1 - e^{-t g / C}); tau = 245.588 s, P/g = 588.235 K.
    ThermalNetwork n;
    const int block = n.add_mass("block", 16.7, 25.0);
    n.set_ambient(25.0);
    n.set_ambient_conductance(block, 0.068);
    n.set_power(block, 40.0);
    double t = 0;
    for (double step : {0.001, 0.5, 10.0, 89.499, 100.0, 300.0}) {
        n.advance(step);
        t += step;
        const double expected = 25.0 + 40.0 / 0.068 * (1.0 - std::exp(-t * 0.068 / 16.7));
        EXPECT_NEAR(n.temperature(block), expected, 1e-9) << "t = " << t;
    }
    // Hand check at t = 100 s: 588.235 * (1 - e^{-0.40719}) = 196.75 K above ambient.
    ThermalNetwork m;
    const int b = m.add_mass("block", 16.7, 25.0);
    m.set_ambient_conductance(b, 0.068);
    m.set_power(b, 40.0);
    m.advance(100.0);
    EXPECT_NEAR(m.temperature(b), 221.75, 0.01);
}

TEST(ThermalNetwork, ManySmallStepsEqualOneBigStep) {
    // Exactness: the state after 10 000 steps of 1 ms equals one step of 10 s.
    auto make = [] {
        ThermalNetwork n;
        const int block = n.add_mass("block", 16.7, 25.0);
        n.add_follower("sensor", block, 1 / 0.22, 25.0);
        n.set_ambient_conductance(block, 0.068);
        n.set_power(block, 40.0);
        return n;
    };
    ThermalNetwork fine = make(), coarse = make();
    for (int i = 0; i < 10000; ++i) fine.advance(0.001);
    coarse.advance(10.0);
    EXPECT_NEAR(fine.temperature(0), coarse.temperature(0), 1e-9);
    EXPECT_NEAR(fine.temperature(1), coarse.temperature(1), 1e-9);
}

// The reference: x(t) from the matrix exponential of [[A, b], [0, 0]] t,
// computed here with Eigen's MatrixFunctions, independently of the network's
// modal solution.
Eigen::VectorXd reference_solution(const ThermalNetwork& n, const Eigen::VectorXd& x0, double t) {
    const Eigen::MatrixXd a = n.a_matrix();
    const Eigen::VectorXd b = n.b_vector();
    const auto k = a.rows();
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(k + 1, k + 1);
    m.topLeftCorner(k, k) = a * t;
    m.topRightCorner(k, 1) = b * t;
    const Eigen::MatrixXd e = m.exp();
    return e.topLeftCorner(k, k) * x0 + e.topRightCorner(k, 1);
}

TEST(ThermalNetwork, ThreeNodesMatchTheMatrixExponential) {
    // The heated_bed shape: heater plate, glass, sensor bead on the plate.
    ThermalNetwork n;
    const int plate = n.add_mass("plate", 158, 25.0);
    const int glass = n.add_mass("glass", 269, 25.0);
    const int bead = n.add_follower("bead", plate, 2.0, 25.0);
    n.set_conductance(plate, glass, 10.0);
    n.set_ambient_conductance(plate, 0.44);
    n.set_ambient_conductance(glass, 0.65);
    n.set_power(plate, 120.0);
    ASSERT_TRUE(n.modal());
    Eigen::VectorXd x0(3);
    x0 << 25.0, 25.0, 25.0;
    const Eigen::VectorXd expected = reference_solution(n, x0, 137.25);
    n.advance(137.25);
    EXPECT_NEAR(n.temperature(plate), expected(0), 1e-9);
    EXPECT_NEAR(n.temperature(glass), expected(1), 1e-9);
    EXPECT_NEAR(n.temperature(bead), expected(2), 1e-9);
    EXPECT_GT(n.temperature(plate), n.temperature(glass));  // heat flows plate -> glass
}

TEST(ThermalNetwork, RepeatedEigenvaluesFallBackToTheMatrixExponential) {
    // A follower whose time constant equals the block's C/g = 10 s makes A
    // defective ([[-0.1, 0], [0.1, -0.1]]): the modal form cannot be used.
    ThermalNetwork n;
    const int block = n.add_mass("block", 10.0, 20.0);
    const int bead = n.add_follower("bead", block, 10.0, 20.0);
    n.set_ambient(20.0);
    n.set_ambient_conductance(block, 1.0);
    n.set_power(block, 50.0);
    EXPECT_FALSE(n.modal());
    n.advance(7.0);
    // Closed forms (tau = 10 s, rise 50 K): block 20 + 50 (1 - e^{-t/tau});
    // bead 20 + 50 (1 - e^{-t/tau} - (t/tau) e^{-t/tau}).
    const double e = std::exp(-0.7);
    EXPECT_NEAR(n.temperature(block), 20 + 50 * (1 - e), 1e-9);
    EXPECT_NEAR(n.temperature(bead), 20 + 50 * (1 - e - 0.7 * e), 1e-9);
}

TEST(ThermalNetwork, EnergyInEqualsStoredPlusLost) {
    ThermalNetwork n;
    const int plate = n.add_mass("plate", 158, 25.0);
    const int glass = n.add_mass("glass", 269, 25.0);
    n.add_follower("bead", plate, 2.0, 25.0);
    n.set_conductance(plate, glass, 10.0);
    n.set_ambient_conductance(plate, 0.44);
    n.set_ambient_conductance(glass, 0.65);
    // A PWM-like input with changes of conductance on the way.
    for (int i = 0; i < 2000; ++i) {
        n.set_power(plate, (i % 3) ? 120.0 : 0.0);
        if (i == 700) n.set_ambient_conductance(glass, 1.3);
        n.advance(0.1 + 0.01 * (i % 7));
    }
    const double in = n.energy_in_J();
    EXPECT_GT(in, 1e4);
    EXPECT_NEAR(n.energy_stored_J() + n.energy_lost_J(), in, 1e-9 * in);
}

TEST(ThermalNetwork, DetachedFollowerRelaxesToAmbient) {
    ThermalNetwork n;
    const int block = n.add_mass("block", 16.7, 200.0);
    const int bead = n.add_follower("bead", block, 1 / 0.22, 200.0);
    n.set_ambient(25.0);
    n.set_follower_source(bead, ThermalNetwork::kAmbient);
    n.advance(10.0);
    // 25 + 175 e^{-10 * 0.22} = 25 + 175 * 0.110803 = 44.39 degC.
    EXPECT_NEAR(n.temperature(bead), 25.0 + 175.0 * std::exp(-2.2), 1e-9);
    EXPECT_NEAR(n.temperature(bead), 44.39, 0.01);
}

}  // namespace
}  // namespace avrbench
