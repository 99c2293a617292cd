#include "parts/HybridStepperModel.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace avrbench {

HybridStepperModel::HybridStepperModel(const Params& params, std::vector<Winding> windings)
    : params_(params), windings_(std::move(windings)) {
    if (windings_.empty() || windings_.size() > kMaxWindings) {
        throw std::invalid_argument("a hybrid stepper has 1 to 4 windings");
    }
    if (params_.resistance_ohm <= 0 || params_.inductance_h <= 0 || params_.inertia_kg_m2 <= 0 ||
        params_.max_step_s <= 0 || params_.rotor_teeth <= 0 || params_.chopper_tau_s <= 0 ||
        params_.coulomb_speed_rad_s <= 0) {
        throw std::invalid_argument("hybrid stepper: resistance, inductance, inertia, steps must be positive");
    }
    inv_l_ = 1.0 / params_.inductance_h;
    inv_j_ = 1.0 / params_.inertia_kg_m2;
    for (std::size_t k = 0; k < windings_.size(); ++k) drive_[k] = WindingDrive::open();
}

void HybridStepperModel::set_drive(std::size_t winding, const WindingDrive& d) {
    const WindingDrive& old = drive_[winding];
    if (old.current_mode != d.current_mode || old.v_pos != d.v_pos || old.v_neg != d.v_neg ||
        old.r_pos != d.r_pos || old.r_neg != d.r_neg || old.target_a != d.target_a || old.supply_v != d.supply_v) {
        settled_ = false;
    }
    drive_[winding] = d;
}

double HybridStepperModel::phase_current(int phase) const {
    double sum = 0;
    for (std::size_t k = 0; k < windings_.size(); ++k) {
        if (windings_[k].phase == phase) sum += windings_[k].sign * x_[static_cast<Eigen::Index>(k)];
    }
    return sum;
}

double HybridStepperModel::back_emf(std::size_t winding) const {
    const double e = params_.rotor_teeth * angle();
    const double g = windings_[winding].phase == 0 ? -std::sin(e) : std::cos(e);
    return windings_[winding].sign * params_.torque_constant_nm_per_a * speed() * g;
}

double HybridStepperModel::motor_torque() const {
    const double e = params_.rotor_teeth * angle();
    const double g[2] = {-std::sin(e), std::cos(e)};
    double t = 0;
    for (std::size_t k = 0; k < windings_.size(); ++k) {
        t += windings_[k].sign * x_[static_cast<Eigen::Index>(k)] * g[windings_[k].phase];
    }
    return params_.torque_constant_nm_per_a * t - params_.detent_torque_nm * std::sin(4.0 * e);
}

HybridStepperModel::Modes HybridStepperModel::choose_modes(const State& x) const {
    Modes modes{};
    double s = 0, c = 0;
    sin_cos(params_.rotor_teeth * x[kMaxWindings + 1], s, c);
    const double g[2] = {-s, c};
    for (std::size_t k = 0; k < windings_.size(); ++k) {
        const WindingDrive& d = drive_[k];
        const double i = x[static_cast<Eigen::Index>(k)];
        if (d.current_mode) {
            modes[k] = Mode::Current;
        } else if (i > 0) {
            modes[k] = Mode::Positive;
        } else if (i < 0) {
            modes[k] = Mode::Negative;
        } else {
            const double emf = windings_[k].sign * params_.torque_constant_nm_per_a * x[kMaxWindings] * g[windings_[k].phase];
            modes[k] = d.v_pos > emf ? Mode::Positive : d.v_neg < emf ? Mode::Negative : Mode::Held;
        }
    }
    return modes;
}

HybridStepperModel::State HybridStepperModel::derivative(const State& x, const Modes& modes, bool at_state) const {
    State dx = State::Zero();
    const double omega = x[kMaxWindings];
    double s = 0, c = 0;
    if (at_state) sin_cos(params_.rotor_teeth * x[kMaxWindings + 1], s, c);
    else sin_cos_uncached(params_.rotor_teeth * x[kMaxWindings + 1], s, c);
    const double g[2] = {-s, c};
    const double r = params_.resistance_ohm;
    double torque_sum = 0;
    for (std::size_t k = 0; k < windings_.size(); ++k) {
        const auto ki = static_cast<Eigen::Index>(k);
        const double i = x[ki];
        const double gk = windings_[k].sign * g[windings_[k].phase];
        torque_sum += i * gk;
        const double emf = params_.torque_constant_nm_per_a * omega * gk;
        const WindingDrive& d = drive_[k];
        switch (modes[k]) {
            case Mode::Positive: dx[ki] = (d.v_pos - d.r_pos * i - r * i - emf) * inv_l_; break;
            case Mode::Negative: dx[ki] = (d.v_neg - d.r_neg * i - r * i - emf) * inv_l_; break;
            case Mode::Held: dx[ki] = 0; break;
            case Mode::Current: {
                const double want = (d.target_a - i) / params_.chopper_tau_s;
                const double hi = (d.supply_v - r * i - emf) * inv_l_;
                const double lo = (-d.supply_v - r * i - emf) * inv_l_;
                dx[ki] = std::clamp(want, lo, hi);
                break;
            }
        }
    }
    // sin(4e) from sin(e), cos(e): sin 2e = 2sc, cos 2e = c^2 - s^2.
    const double sin4 = 2.0 * (2.0 * s * c) * (c * c - s * s);
    const double torque = params_.torque_constant_nm_per_a * torque_sum - params_.detent_torque_nm * sin4 -
                          params_.viscous_nm_s_per_rad * omega - params_.coulomb_nm * friction_shape(omega, at_state) -
                          params_.load_torque_nm;
    dx[kMaxWindings] = torque * inv_j_;
    dx[kMaxWindings + 1] = omega;
    return dx;
}

HybridStepperModel::State HybridStepperModel::rk4(const State& x, double h, const Modes& modes) const {
    const State k1 = derivative(x, modes, true);
    const State k2 = derivative(x + 0.5 * h * k1, modes, false);
    const State k3 = derivative(x + 0.5 * h * k2, modes, false);
    const State k4 = derivative(x + h * k3, modes, false);
    return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

// Event function of winding k in mode `mode`: for a conducting winding its
// current (the event is the current reaching zero); for a blocked one the
// margin by which the circuit could start a current against the back-EMF
// (max(v_pos - e, e - v_neg), negative inside the diodes' dead zone).
double HybridStepperModel::event_value(const State& x, std::size_t k, Mode mode) const {
    const auto ki = static_cast<Eigen::Index>(k);
    if (mode != Mode::Held) return x[ki];
    double s = 0, c = 0;
    sin_cos(params_.rotor_teeth * x[kMaxWindings + 1], s, c);
    const double g = windings_[k].phase == 0 ? -s : c;
    const double emf = windings_[k].sign * params_.torque_constant_nm_per_a * x[kMaxWindings] * g;
    return std::max(drive_[k].v_pos - emf, emf - drive_[k].v_neg);
}

// The direction a blocked winding starts to conduct in, at state x.
HybridStepperModel::Mode HybridStepperModel::conducting_mode(const State& x, std::size_t k) const {
    double s = 0, c = 0;
    sin_cos(params_.rotor_teeth * x[kMaxWindings + 1], s, c);
    const double g = windings_[k].phase == 0 ? -s : c;
    const double emf = windings_[k].sign * params_.torque_constant_nm_per_a * x[kMaxWindings] * g;
    return drive_[k].v_pos - emf > emf - drive_[k].v_neg ? Mode::Positive : Mode::Negative;
}

double HybridStepperModel::step(double h) {
    Modes modes = choose_modes(x_);
    State next = rk4(x_, h, modes);
    ++rk4_steps_;
    // The earliest mode change inside the step: a conducting winding's
    // current reaching zero, or a blocked winding starting to conduct.
    double first_s = 2.0;
    std::size_t event = kMaxWindings;
    for (std::size_t k = 0; k < windings_.size(); ++k) {
        const auto ki = static_cast<Eigen::Index>(k);
        double f0 = 0, f1 = 0;
        if (modes[k] == Mode::Positive || modes[k] == Mode::Negative) {
            f0 = x_[ki];
            f1 = next[ki];
            if (!((modes[k] == Mode::Positive && f1 < 0) || (modes[k] == Mode::Negative && f1 > 0))) continue;
            if (f0 == 0) {
                // Started at zero and the back-EMF turned it round within the
                // step (the margin was tiny): blocked for this step instead.
                modes[k] = Mode::Held;
                next = rk4(x_, h, modes);
                ++rk4_steps_;
                continue;
            }
        } else if (modes[k] == Mode::Held) {
            f0 = event_value(x_, k, Mode::Held);
            f1 = event_value(next, k, Mode::Held);
            if (f1 <= 0) continue;
            if (f0 >= -1e-12) {
                // On the edge of the dead zone already (a current that just
                // decayed to zero as the back-EMF reached the diodes' drop):
                // it conducts from the start of the step.
                modes[k] = conducting_mode(next, k);
                next = rk4(x_, h, modes);
                ++rk4_steps_;
                continue;
            }
        } else {
            continue;
        }
        const double s = f0 / (f0 - f1);
        if (s < first_s) {
            first_s = s;
            event = k;
        }
    }
    if (event == kMaxWindings) {
        x_ = next;
        return h;
    }
    // Locate the event on the RK4 solution from x_ by the Illinois variant of
    // regula falsi, then step to just past it: the next step starts in the
    // new mode with the current exactly zero.
    const Mode mode = modes[event];
    double t_lo = 0, f_lo = event_value(x_, event, mode);
    double t_hi = h, f_hi = event_value(next, event, mode);
    State past = next;
    int side = 0;
    for (int iter = 0; iter < 8 && t_hi - t_lo > h * 1e-9; ++iter) {
        const double t = t_lo + (t_hi - t_lo) * f_lo / (f_lo - f_hi);
        const State trial = rk4(x_, t, modes);
        ++rk4_steps_;
        const double f = event_value(trial, event, mode);
        if (f == 0 || (f > 0) != (f_lo > 0)) {
            t_hi = t;
            f_hi = f;
            past = trial;
            if (side == +1) f_lo *= 0.5;
            side = +1;
        } else {
            t_lo = t;
            f_lo = f;
            if (side == -1) f_hi *= 0.5;
            side = -1;
        }
    }
    if (mode != Mode::Held) past[static_cast<Eigen::Index>(event)] = 0;
    // Any other conducting winding that crossed before t_hi is cut as well.
    for (std::size_t k = 0; k < windings_.size(); ++k) {
        const auto ki = static_cast<Eigen::Index>(k);
        if ((modes[k] == Mode::Positive && past[ki] < 0) || (modes[k] == Mode::Negative && past[ki] > 0)) past[ki] = 0;
    }
    x_ = past;
    ++zero_crossings_;
    return t_hi;
}

void HybridStepperModel::advance(double seconds) {
    if (seconds <= 0 || settled_) return;
    double left = seconds;
    // Guards against a zero-length cut repeating: a cut always advances at
    // least a small fraction of the step.
    const double min_cut = params_.max_step_s * 1e-9;
    while (left > 0) {
        const double h = std::min(left, params_.max_step_s);
        double done = step(h);
        if (done < min_cut) done = std::min(min_cut, left);
        left -= done;
        if (left < params_.max_step_s * 1e-12) break;
    }
    check_settled();
}

void HybridStepperModel::check_settled() {
    // A turning rotor is not settled, whatever its acceleration (the test
    // below, without working the derivative out: most checks are made while
    // the motor moves).
    if (!(std::abs(x_[kMaxWindings]) < 1e-7)) {
        settled_ = false;
        return;
    }
    const Modes modes = choose_modes(x_);
    const State dx = derivative(x_, modes, true);
    // Nothing will move: the rotor at rest without acceleration, every current
    // within 1 nA of its end value (|di/dt| * L/R).
    const double tau = params_.inductance_h / params_.resistance_ohm;
    bool still = std::abs(x_[kMaxWindings]) < 1e-7 && std::abs(dx[kMaxWindings]) < 1e-4;
    for (std::size_t k = 0; k < windings_.size() && still; ++k) {
        still = std::abs(dx[static_cast<Eigen::Index>(k)]) * tau < 1e-9;
    }
    settled_ = still;
}

}  // namespace avrbench
