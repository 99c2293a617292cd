// The hybrid stepper physics on its own (no MCU): the electrical part against
// the closed-form R-L solution, the integrator's order of accuracy, and the
// pull-out point's independence of the integration step.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "parts/HybridStepperModel.hpp"

namespace avrbench {
namespace {

constexpr double kPi = 3.14159265358979323846;

// SM-42BYG011-25 as the seed 003 board file has it (preset + calibrated load).
HybridStepperModel::Params sm42(double max_step_s) {
    HybridStepperModel::Params p;
    p.rotor_teeth = 50;
    p.resistance_ohm = 34;
    p.inductance_h = 46e-3;
    p.torque_constant_nm_per_a = 0.607;
    p.detent_torque_nm = 0.015;
    p.inertia_kg_m2 = 35e-7 + 215e-7;
    p.viscous_nm_s_per_rad = 5e-4;
    p.coulomb_nm = 0.002;
    p.max_step_s = max_step_s;
    return p;
}

// An L293D half-bridge pair from its datasheet drops (TI SLRS008C, typical:
// V_OH = Vs - 1.4 V, V_OL = 1.2 V, clamp diodes 1.3 V), 12 V supply, written
// out independently of the L293D part: +1 = (H, L), -1 = (L, H), 0 = (L, L).
WindingDrive l293d(int polarity) {
    WindingDrive d;
    if (polarity > 0) {
        d.v_pos = 12 - 1.4 - 1.2;  // source high, sink low
        d.v_neg = 12 + 1.3 + 1.3;  // both clamp diodes back into the supply
    } else if (polarity < 0) {
        d.v_pos = -(12 + 1.3 + 1.3);
        d.v_neg = -(12 - 1.4 - 1.2);
    } else {
        d.v_pos = -1.3 - 1.2;  // lower clamp diode + low-side transistor
        d.v_neg = 1.2 + 1.3;
    }
    d.polarity = polarity;
    return d;
}

const int kDouble[4][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};  // A+B+, B+A-, A-B-, B-A+
const int kSingle[4][2] = {{0, 1}, {-1, 0}, {0, -1}, {1, 0}};    // B+, A-, B-, A+

TEST(StepperModel, WindingCurrentRisesAsTheRlExponential) {
    // A rotor too heavy to move: the winding is a plain R-L circuit.
    // i(t) = V/R (1 - exp(-t R / L)); L/R = 46 mH / 34 ohm = 1.353 ms.
    auto p = sm42(20e-6);
    p.inertia_kg_m2 = 1e6;
    HybridStepperModel m(p, {{0, 1}, {1, 1}});
    WindingDrive on;
    on.v_pos = 9.4;
    on.v_neg = 14.6;
    m.set_drive(0, on);
    const double tau = 46e-3 / 34.0;
    double t = 0;
    for (double target : {0.5 * tau, tau, 3 * tau}) {
        m.advance(target - t);
        t = target;
        EXPECT_NEAR(m.current(0), 9.4 / 34 * (1 - std::exp(-t / tau)), 1e-9) << "t = " << t;
    }
    EXPECT_EQ(m.current(1), 0.0);  // the open winding carries nothing
}

TEST(StepperModel, BrakedWindingDecaysSlowerThanAnOpenOne) {
    // From 9.4 V / 34 ohm, a winding shorted through one transistor and one
    // diode (both inputs low, -2.5 V) reaches zero after tau ln(1 + 9.4/2.5)
    // = 2.11 ms; an open one (both outputs off, -14.6 V through the clamp
    // diodes into the supply) after tau ln(1 + 9.4/14.6) = 0.673 ms; then it
    // stays at zero (the diodes block the other direction).
    const double tau = 46e-3 / 34.0;
    for (bool braked : {true, false}) {
        auto p = sm42(20e-6);
        p.inertia_kg_m2 = 1e6;
        HybridStepperModel m(p, {{0, 1}, {1, 1}});
        m.set_drive(0, l293d(+1));
        m.advance(30 * tau);
        ASSERT_NEAR(m.current(0), 9.4 / 34, 1e-9);
        WindingDrive off = braked ? l293d(0) : WindingDrive{};
        if (!braked) {
            off.v_pos = -14.6;
            off.v_neg = 14.6;
        }
        m.set_drive(0, off);
        const double t_zero = tau * std::log(1 + 9.4 / (braked ? 2.5 : 14.6));
        m.advance(t_zero - 2e-6);
        EXPECT_GT(m.current(0), 0) << (braked ? "braked" : "open");
        m.advance(4e-6);
        EXPECT_EQ(m.current(0), 0) << (braked ? "braked" : "open");
        m.advance(5e-3);
        EXPECT_EQ(m.current(0), 0) << (braked ? "braked" : "open");
    }
}

TEST(StepperModel, BackEmfAndTorqueShareOneConstant) {
    // Energy balance (seed 003 digest §6.1): sum of e_k i_k = T_em omega.
    auto p = sm42(20e-6);
    HybridStepperModel m(p, {{0, 1}, {1, 1}});
    m.set_drive(0, l293d(+1));
    m.set_drive(1, l293d(-1));
    m.advance(3.7e-3);  // somewhere mid-swing: currents, speed and angle all nonzero
    ASSERT_GT(std::fabs(m.speed()), 0.1);
    const double theta = m.angle();
    const double detent = -0.015 * std::sin(4 * 50 * theta);
    const double em_torque = m.motor_torque() - detent;
    const double electrical = m.back_emf(0) * m.current(0) + m.back_emf(1) * m.current(1);
    EXPECT_NEAR(electrical, em_torque * m.speed(), 1e-9 * std::fabs(electrical) + 1e-12);
}

// A speed sweep of the pure model: +1 rpm every `steps_per_rpm` full steps
// from 100 rpm, returning the excitation speed at the first pole slip.
double sweep_stall_rpm(double max_step_s, int steps_per_rpm) {
    HybridStepperModel m(sm42(max_step_s), {{0, 1}, {1, 1}});
    const double nr = 50;
    for (int step = 0; step < 100000; ++step) {
        const double rpm = 100 + step / steps_per_rpm;
        const int* e = kDouble[step % 4];
        m.set_drive(0, l293d(e[0]));
        m.set_drive(1, l293d(e[1]));
        const double command_e = kPi / 4 + step * kPi / 2;
        const double dt = 60.0 / (200 * rpm);
        for (int k = 0; k < 10; ++k) {
            m.advance(dt / 10);
            if (command_e - nr * m.angle() > 1.25 * kPi) return rpm;
        }
    }
    return -1;
}

TEST(StepperModel, PullOutSpeedDoesNotDriftWithTheStepSize) {
    // +1 rpm every 50 full steps; the stall speed must not depend on the RK4
    // step between 5 us and 40 us (4x the default's range each way).
    const double reference = sweep_stall_rpm(5e-6, 50);
    ASSERT_GT(reference, 150);
    EXPECT_EQ(sweep_stall_rpm(20e-6, 50), reference);
    EXPECT_EQ(sweep_stall_rpm(40e-6, 50), reference);
}

// The state after a fixed excitation sequence with every kind of event in
// it (one- and two-phase steps, braked and open windings, diode
// commutations), at one integration step.
HybridStepperModel::State run_sequence(double max_step_s) {
    HybridStepperModel m(sm42(max_step_s), {{0, 1}, {1, 1}});
    for (int s = 0; s < 300; ++s) {
        const double rpm = 100 + s * 0.5;
        const int* e = s < 100 ? kSingle[s % 4] : kDouble[s % 4];
        m.set_drive(0, l293d(e[0]));
        m.set_drive(1, l293d(e[1]));
        if (s == 200) {
            WindingDrive open;
            open.v_pos = -14.6;
            open.v_neg = 14.6;
            m.set_drive(0, open);
            m.set_drive(1, open);
            m.advance(0.3e-3);
            m.set_drive(0, l293d(e[0]));
            m.set_drive(1, l293d(e[1]));
        }
        m.advance(60.0 / (200 * rpm));
    }
    return m.state();
}

TEST(StepperModel, IntegrationErrorIsFourthOrderInTheStep) {
    // Against a 1 us reference: halving the step divides the angle and speed
    // errors by about 2^4 = 16 (RK4 with located diode events); at the
    // default 20 us the angle error after 0.3 s of stepping is below 1e-8 rad.
    const auto ref = run_sequence(1e-6);
    auto err = [&](double h) {
        const auto s = run_sequence(h);
        return std::fabs(s[5] - ref[5]) + std::fabs(s[4] - ref[4]) * 1e-3;
    };
    const double e10 = err(10e-6), e20 = err(20e-6), e40 = err(40e-6);
    EXPECT_LT(e20, 1e-8);
    EXPECT_GT(e20 / e10, 8.0);
    EXPECT_GT(e40 / e20, 8.0);
}

}  // namespace
}  // namespace avrbench
