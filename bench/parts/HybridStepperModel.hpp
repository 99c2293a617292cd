// The physics of a two-phase hybrid stepper motor (no pins, no time base of
// its own): per winding an R-L circuit with back-EMF, electromagnetic torque
// from the phase currents and the rotor angle, detent torque, rotor plus load
// inertia, viscous and Coulomb friction and a load torque. The part that owns
// it (HybridStepper) feeds it the windings' drives and advances it between pin
// events. docs/MOTOR.md has the equations, parameter sources and the measured
// integration error.
//
// Equations (Acarnley; Kenjo & Sugawara; the sign convention of seed 003's
// digest §6.1, so that A+ holds the rotor at theta = 0 and B+ at one full step
// ahead, and the sequence A+, B+, A-, B- turns it forward):
//   g_A(theta) = -sin(Nr*theta),  g_B(theta) = cos(Nr*theta)
//   winding k (phase p_k, sign s_k):   L di_k/dt = v_k - R i_k - s_k Km omega g_{p_k}
//   T_em = Km * sum_k s_k i_k g_{p_k}  -  T_detent sin(4 Nr theta)
//   J domega/dt = T_em - B omega - T_c tanh(omega/omega_c) - T_load
//   dtheta/dt = omega
// A bipolar motor has two windings (A: phase A, +; B: phase B, +). A unipolar
// (six-wire) motor has four half-windings A, B, C = A-, D = B-, each with its
// own R and L; the magnetic coupling between the two halves of a phase is not
// modelled.
//
// Integration: classical Runge-Kutta 4 with a fixed maximum step. Pin events
// fall on step boundaries (advance() integrates exactly up to them), so the
// drive is constant within a step. Each winding's conduction mode (current
// positive, negative, or held at zero by diodes) is fixed for a step; when
// the mode would change inside a step (a current reaching zero, or a blocked
// winding whose back-EMF overcomes the diodes' dead zone), the event is
// located by Illinois regula falsi on the RK4 solution, the step is cut just
// past it (a current set to exactly zero), and the next step starts in the
// new mode. Coulomb friction is smoothed by tanh so the right-hand side is
// smooth within a step.
#pragma once

#include <Eigen/Core>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <cstdint>
#include <vector>

#include "parts/WindingDrive.hpp"

namespace avrbench {

class HybridStepperModel {
public:
    static constexpr int kMaxWindings = 4;
    using State = Eigen::Matrix<double, kMaxWindings + 2, 1>;  // i_0..i_3, omega, theta

    struct Params {
        int rotor_teeth = 50;                   // Nr: 50 for a 1.8 degree motor
        double resistance_ohm = 34;             // per winding
        double inductance_h = 46e-3;            // per winding
        double torque_constant_nm_per_a = 0.5;  // Km, N*m/A (= V*s/rad), per winding
        double detent_torque_nm = 0;            // amplitude, N*m
        double inertia_kg_m2 = 3.5e-6;          // rotor + load, kg*m^2
        double viscous_nm_s_per_rad = 0;        // B, N*m*s/rad
        double coulomb_nm = 0;                  // T_c, N*m
        double coulomb_speed_rad_s = 0.05;      // omega_c of the tanh smoothing, rad/s
        double load_torque_nm = 0;              // N*m, acts towards -theta
        double max_step_s = 10e-6;              // RK4 step bound
        double chopper_tau_s = 20e-6;           // current-mode tracking time constant
    };
    struct Winding {
        int phase;  // 0 = A, 1 = B
        int sign;   // +1 or -1: the direction of its flux
    };

    HybridStepperModel(const Params& params, std::vector<Winding> windings);

    // The drive of winding k from now on.
    void set_drive(std::size_t winding, const WindingDrive& drive);
    const WindingDrive& drive(std::size_t winding) const { return drive_[winding]; }

    // Integrates `seconds` forward with the current drives.
    void advance(double seconds);

    std::size_t winding_count() const { return windings_.size(); }
    double current(std::size_t winding) const { return x_[static_cast<Eigen::Index>(winding)]; }
    // Net current of phase 0 (A) or 1 (B): sum of sign * current of its windings.
    double phase_current(int phase) const;
    double speed() const { return x_[kMaxWindings]; }       // rad/s
    double angle() const { return x_[kMaxWindings + 1]; }   // rad, mechanical
    double electrical_angle() const { return angle() * params_.rotor_teeth; }
    // Back-EMF of winding k at the present state, V (the voltage it opposes).
    double back_emf(std::size_t winding) const;
    // Electromagnetic + detent torque at the present state, N*m.
    double motor_torque() const;
    const State& state() const { return x_; }
    void set_angle(double theta) { x_[kMaxWindings + 1] = theta; settled_ = false; }
    const Params& params() const { return params_; }

    // True when nothing changes any more with the present drives (currents at
    // their steady values, rotor at rest); advance() is then free.
    bool settled() const { return settled_; }
    std::uint64_t rk4_steps() const { return rk4_steps_; }
    std::uint64_t mode_events() const { return zero_crossings_; }  // diode commutations located

private:
    enum class Mode : std::int8_t { Positive, Negative, Held, Current };
    using Modes = std::array<Mode, kMaxWindings>;

    Modes choose_modes(const State& x) const;
    // dx/dt at x. `at_state`: x is a state the model stops at (x_, a step's
    // end, a located event), whose sin, cos and friction term are asked for
    // again by the mode choice, the events and the settled check; an RK4
    // stage point is not, and must not push them out of the cache.
    State derivative(const State& x, const Modes& modes, bool at_state) const;
    State rk4(const State& x, double h, const Modes& modes) const;
    double event_value(const State& x, std::size_t winding, Mode mode) const;
    Mode conducting_mode(const State& x, std::size_t winding) const;
    // One step of at most h; returns the time actually advanced (shorter when
    // a winding current reached zero).
    double step(double h);
    void check_settled();
    // sin and cos of the electrical angle `e`, remembered for the last two
    // states asked: a step's mode choice and first RK4 stage, its events and
    // the settled check after it all ask at the same state, and the events
    // of a blocked winding ask at the step's start and end in turn, once per
    // blocked winding (the same values as computing them anew: one
    // function, one argument).
    void sin_cos(double e, double& s, double& c) const {
        // Compared bit for bit: -0.0 == +0.0, but their sines differ in sign.
        const auto bits = std::bit_cast<std::uint64_t>(e);
        for (const Trig& t : trig_) {
            if (bits == std::bit_cast<std::uint64_t>(t.angle)) {
                s = t.sin;
                c = t.cos;
                return;
            }
        }
        sin_cos_uncached(e, s, c);
        trig_[trig_next_] = Trig{e, s, c};
        trig_next_ ^= 1;
    }
    static void sin_cos_uncached(double e, double& s, double& c) {
        s = std::sin(e);
        c = std::cos(e);
    }
    // The Coulomb friction's tanh at speed `omega` (rad/s), remembered like sin_cos.
    double friction_shape(double omega, bool at_state) const {
        if (!at_state) return std::tanh(omega / params_.coulomb_speed_rad_s);
        if (std::bit_cast<std::uint64_t>(omega) != std::bit_cast<std::uint64_t>(friction_omega_)) {
            friction_omega_ = omega;
            friction_tanh_ = std::tanh(omega / params_.coulomb_speed_rad_s);
        }
        return friction_tanh_;
    }

    Params params_;
    std::vector<Winding> windings_;
    std::array<WindingDrive, kMaxWindings> drive_{};
    State x_ = State::Zero();
    double inv_l_, inv_j_;
    bool settled_ = false;
    std::uint64_t rk4_steps_ = 0;
    std::uint64_t zero_crossings_ = 0;
    // The caches start at NaN, their values too: sin, cos and tanh of NaN.
    static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    struct Trig {
        double angle, sin, cos;
    };
    mutable std::array<Trig, 2> trig_{Trig{kNaN, kNaN, kNaN}, Trig{kNaN, kNaN, kNaN}};  // sin_cos
    mutable unsigned trig_next_ = 0;                                                    // the one to replace
    mutable double friction_omega_ = kNaN, friction_tanh_ = kNaN;           // friction_shape
};

}  // namespace avrbench
