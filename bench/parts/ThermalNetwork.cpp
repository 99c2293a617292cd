#include "parts/ThermalNetwork.hpp"

#include <cmath>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>

namespace avrbench {

void ThermalNetwork::check_node(int node, const char* what) const {
    if (node < 0 || node >= node_count()) throw std::out_of_range(std::string("ThermalNetwork: bad node for ") + what);
}

int ThermalNetwork::add_mass(std::string name, double heat_capacity_J_per_K, double initial_degC) {
    if (!(heat_capacity_J_per_K > 0)) throw std::invalid_argument("ThermalNetwork: a mass needs a positive heat capacity");
    if (node_count() >= kMaxNodes) throw std::length_error("ThermalNetwork: too many nodes");
    Node n;
    n.name = std::move(name);
    n.capacity = heat_capacity_J_per_K;
    nodes_.push_back(n);
    x_.push_back(initial_degC);
    reference_.push_back(initial_degC);
    for (auto& row : g_) row.push_back(0);
    g_.emplace_back(nodes_.size(), 0.0);
    model_dirty_ = input_dirty_ = true;
    return node_count() - 1;
}

int ThermalNetwork::add_follower(std::string name, int source, double time_constant_s, double initial_degC) {
    if (!(time_constant_s > 0)) throw std::invalid_argument("ThermalNetwork: a follower needs a positive time constant");
    if (source != kAmbient) check_node(source, "follower source");
    if (node_count() >= kMaxNodes) throw std::length_error("ThermalNetwork: too many nodes");
    Node n;
    n.name = std::move(name);
    n.source = source;
    n.tau = time_constant_s;
    nodes_.push_back(n);
    x_.push_back(initial_degC);
    reference_.push_back(initial_degC);
    for (auto& row : g_) row.push_back(0);
    g_.emplace_back(nodes_.size(), 0.0);
    model_dirty_ = input_dirty_ = true;
    return node_count() - 1;
}

int ThermalNetwork::find(const std::string& name) const {
    for (int i = 0; i < node_count(); ++i) {
        if (nodes_[i].name == name) return i;
    }
    return -1;
}

void ThermalNetwork::set_conductance(int a, int b, double W_per_K) {
    check_node(a, "conductance");
    check_node(b, "conductance");
    if (!is_mass(a) || !is_mass(b) || a == b) throw std::invalid_argument("ThermalNetwork: conductances join two masses");
    if (g_[a][b] == W_per_K) return;
    g_[a][b] = g_[b][a] = W_per_K;
    model_dirty_ = true;
}

void ThermalNetwork::set_ambient_conductance(int node, double W_per_K) {
    check_node(node, "ambient conductance");
    if (!is_mass(node)) throw std::invalid_argument("ThermalNetwork: only masses lose heat to ambient");
    if (nodes_[node].ambient_g == W_per_K) return;
    nodes_[node].ambient_g = W_per_K;
    model_dirty_ = true;
}

void ThermalNetwork::set_follower_source(int follower, int source) {
    check_node(follower, "follower");
    if (is_mass(follower)) throw std::invalid_argument("ThermalNetwork: not a follower");
    if (source != kAmbient) check_node(source, "follower source");
    if (nodes_[follower].source == source) return;
    nodes_[follower].source = source;
    model_dirty_ = true;
}

void ThermalNetwork::set_ambient(double degC) {
    if (ambient_ == degC) return;
    ambient_ = degC;
    input_dirty_ = true;
}

void ThermalNetwork::set_power(int node, double W) {
    check_node(node, "power");
    if (!is_mass(node)) throw std::invalid_argument("ThermalNetwork: power goes into a mass");
    if (nodes_[node].power == W) return;
    nodes_[node].power = W;
    input_dirty_ = true;
}

void ThermalNetwork::set_temperature(int node, double degC) {
    check_node(node, "temperature");
    x_[node] = degC;
}

double ThermalNetwork::energy_stored_J() const {
    double e = 0;
    for (int i = 0; i < node_count(); ++i) e += nodes_[i].capacity * (x_[i] - reference_[i]);
    return e;
}

void ThermalNetwork::reset_energy() {
    energy_in_J_ = energy_lost_J_ = 0;
    reference_ = x_;
}

Eigen::MatrixXd ThermalNetwork::a_matrix() const {
    const int n = node_count();
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        const Node& node = nodes_[i];
        if (node.capacity > 0) {
            double out = node.ambient_g;
            for (int j = 0; j < n; ++j) {
                if (j == i || g_[i][j] == 0) continue;
                out += g_[i][j];
                a(i, j) = g_[i][j] / node.capacity;
            }
            a(i, i) = -out / node.capacity;
        } else {
            a(i, i) = -1.0 / node.tau;
            if (node.source != kAmbient) a(i, node.source) += 1.0 / node.tau;
        }
    }
    return a;
}

Eigen::VectorXd ThermalNetwork::b_vector() const {
    Eigen::VectorXd b;
    fill_b_vector(b);
    return b;
}

// In place: a heater edge changes b, and allocating per edge (125 k edges/s on
// a bed's PWM) would cost more than the update itself.
void ThermalNetwork::fill_b_vector(Eigen::VectorXd& b) const {
    const int n = node_count();
    if (b.size() != n) b.resize(n);
    b.setZero();
    for (int i = 0; i < n; ++i) {
        const Node& node = nodes_[i];
        if (node.capacity > 0) {
            b(i) = (node.power + node.ambient_g * ambient_) / node.capacity;
        } else if (node.source == kAmbient) {
            b(i) = ambient_ / node.tau;
        }
    }
}

bool ThermalNetwork::modal() const {
    if (model_dirty_) rebuild();
    return modal_;
}

void ThermalNetwork::rebuild() const {
    const int n = node_count();
    a_ = a_matrix();
    ++decompositions_;
    modal_ = false;
    if (n > 0) {
        Eigen::EigenSolver<Eigen::MatrixXd> solver(a_, true);
        if (solver.info() == Eigen::Success) {
            const Eigen::VectorXcd values = solver.eigenvalues();
            double scale = 0, imag = 0;
            for (int i = 0; i < n; ++i) {
                scale = std::max(scale, std::abs(values(i)));
                imag = std::max(imag, std::abs(values(i).imag()));
            }
            if (imag <= 1e-12 * std::max(scale, 1e-300)) {
                v_ = solver.eigenvectors().real();
                Eigen::FullPivLU<Eigen::MatrixXd> lu(v_);
                if (lu.isInvertible()) {
                    v_inv_ = lu.inverse();
                    // A nearly defective matrix has nearly parallel eigenvectors:
                    // the modal form would lose digits, so use the matrix exponential.
                    const double condition = v_.lpNorm<Eigen::Infinity>() * v_inv_.lpNorm<Eigen::Infinity>();
                    if (condition < 1e8) {
                        lambda_ = values.real();
                        modal_ = true;
                    }
                }
            }
        }
    }
    Eigen::RowVectorXd g(n);
    for (int i = 0; i < n; ++i) g(i) = nodes_[i].ambient_g;
    if (modal_) loss_row_ = g * v_;
    model_dirty_ = false;
    input_dirty_ = true;
}

void ThermalNetwork::rebuild_input() const {
    fill_b_vector(b_);
    input_dirty_ = false;
    for (const InputMemo& m : input_memo_) {
        if (m.model == decompositions_ && m.ambient_degC == ambient_ && m.b.size() == b_.size() && m.b == b_) {
            if (modal_) w_ = m.w;
            loss_offset_ = m.loss_offset;
            return;
        }
    }
    if (modal_) {
        if (w_.size() != b_.size()) w_.resize(b_.size());
        w_.noalias() = v_inv_ * b_;
    }
    loss_offset_ = 0;
    for (const auto& node : nodes_) loss_offset_ += node.ambient_g * ambient_;
    InputMemo& m = input_memo_[input_memo_next_];
    input_memo_next_ = (input_memo_next_ + 1) % 2u;
    m.b = b_;
    m.w = w_;
    m.loss_offset = loss_offset_;
    m.ambient_degC = ambient_;
    m.model = decompositions_;
}

void ThermalNetwork::advance(double dt_s) {
    if (!(dt_s > 0)) return;
    if (model_dirty_) rebuild();
    if (input_dirty_) rebuild_input();
    const int n = node_count();
    double power = 0;
    for (const auto& node : nodes_) power += node.power;
    energy_in_J_ += power * dt_s;
    time_s_ += dt_s;
    if (!modal_) {
        advance_van_loan(dt_s);
        return;
    }
    std::array<double, kMaxNodes> z{}, zi{};
    for (int i = 0; i < n; ++i) {
        double s = 0;
        for (int j = 0; j < n; ++j) s += v_inv_(i, j) * x_[j];
        z[i] = s;
    }
    const StepMemo* memo = nullptr;
    for (const StepMemo& m : step_memo_) {
        if (m.model == decompositions_ && m.dt_s == dt_s) memo = &m;
    }
    if (memo == nullptr) {
        StepMemo& m = step_memo_[step_memo_next_];
        step_memo_next_ = (step_memo_next_ + 1) % 2u;
        m.dt_s = dt_s;
        m.model = decompositions_;
        for (int i = 0; i < n; ++i) {
            const double l = lambda_(i);
            const double x = l * dt_s;
            double e, p1, p2;  // e^{λt}, ∫e^{λs}ds, ∫∫
            if (std::abs(x) < 1e-3) {
                e = std::exp(x);
                p1 = dt_s * (1 + x * (1.0 / 2 + x * (1.0 / 6 + x * (1.0 / 24))));
                p2 = dt_s * dt_s * (1.0 / 2 + x * (1.0 / 6 + x * (1.0 / 24 + x * (1.0 / 120))));
            } else {
                const double em1 = std::expm1(x);
                e = em1 + 1;
                p1 = em1 / l;
                p2 = (p1 - dt_s) / l;
            }
            m.e[i] = e;
            m.p1[i] = p1;
            m.p2[i] = p2;
        }
        memo = &m;
    }
    double lost = -loss_offset_ * dt_s;
    for (int i = 0; i < n; ++i) {
        zi[i] = memo->p1[i] * z[i] + memo->p2[i] * w_(i);  // ∫ z over the interval
        z[i] = memo->e[i] * z[i] + memo->p1[i] * w_(i);
        lost += loss_row_(i) * zi[i];
    }
    for (int i = 0; i < n; ++i) {
        double s = 0;
        for (int j = 0; j < n; ++j) s += v_(i, j) * z[j];
        x_[i] = s;
    }
    energy_lost_J_ += lost;
}

void ThermalNetwork::advance_van_loan(double dt_s) {
    // d/dt [x; 1; q] = [[A, b, 0]; [0, 0, 0]; [I, 0, 0]] [x; 1; q], q = ∫x.
    const int n = node_count();
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(2 * n + 1, 2 * n + 1);
    m.topLeftCorner(n, n) = a_ * dt_s;
    m.block(0, n, n, 1) = b_ * dt_s;
    m.block(n + 1, 0, n, n) = Eigen::MatrixXd::Identity(n, n) * dt_s;
    const Eigen::MatrixXd e = m.exp();
    Eigen::VectorXd x0(n);
    for (int i = 0; i < n; ++i) x0(i) = x_[i];
    const Eigen::VectorXd x1 = e.topLeftCorner(n, n) * x0 + e.block(0, n, n, 1);
    const Eigen::VectorXd q = e.block(n + 1, 0, n, n) * x0 + e.block(n + 1, n, n, 1);
    double lost = -loss_offset_ * dt_s;
    for (int i = 0; i < n; ++i) {
        lost += nodes_[i].ambient_g * q(i);
        x_[i] = x1(i);
    }
    energy_lost_J_ += lost;
}

}  // namespace avrbench
