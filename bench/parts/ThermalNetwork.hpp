// A lumped linear thermal network, solved exactly between events.
//
// Nodes are either masses (a heat capacity C, J/K) joined to each other and
// to ambient by conductances (W/K) and heated by a power input (W), or
// massless followers (a sensor bead) that relax towards a source node (or
// ambient) with their own time constant and draw no heat:
//
//     mass i:      C_i dT_i/dt = P_i − g_i (T_i − T_amb) − Σ_j G_ij (T_i − T_j)
//     follower k:  τ_k dT_k/dt = T_source − T_k
//
// which is dx/dt = A x + b with A and b constant between events (a power
// switched, a conductance changed). advance(dt) applies the exact solution
// for constant inputs: with A = V Λ V⁻¹ (real eigenvalues: the masses form
// a matrix similar to a symmetric one, followers add their own −1/τ),
// z = V⁻¹x evolves as z_i(dt) = e^{λ_i dt} z_i + φ1(λ_i, dt) w_i, w = V⁻¹b,
// φ1 = (e^{λdt} − 1)/λ. If the decomposition is not usable (repeated
// eigenvalues, a defective matrix) it falls back to the matrix exponential of
// the augmented system (Van Loan), same result. The heat lost to ambient is
// integrated exactly too (∫x over the interval), so the energy balance
// in = stored + lost holds to rounding.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

namespace avrbench {

class ThermalNetwork {
public:
    static constexpr int kAmbient = -1;
    static constexpr int kMaxNodes = 8;

    int add_mass(std::string name, double heat_capacity_J_per_K, double initial_degC);
    int add_follower(std::string name, int source, double time_constant_s, double initial_degC);

    void set_conductance(int a, int b, double W_per_K);      // between two masses
    void set_ambient_conductance(int node, double W_per_K);  // mass to ambient
    void set_follower_source(int follower, int source);      // a mass, or kAmbient
    void set_ambient(double degC);
    void set_power(int node, double W);                      // heat into a mass

    // Advances by dt seconds with the current inputs held constant.
    void advance(double dt_s);

    int node_count() const { return static_cast<int>(nodes_.size()); }
    int find(const std::string& name) const;  // -1 if absent
    const std::string& node_name(int node) const { return nodes_[node].name; }
    double temperature(int node) const { return x_[node]; }
    void set_temperature(int node, double degC);  // resets that node (tests, initial conditions)
    double ambient() const { return ambient_; }
    double power(int node) const { return nodes_[node].power; }
    double ambient_conductance(int node) const { return nodes_[node].ambient_g; }
    double heat_capacity(int node) const { return nodes_[node].capacity; }
    bool is_mass(int node) const { return nodes_[node].capacity > 0; }
    int follower_source(int node) const { return nodes_[node].source; }
    double time_s() const { return time_s_; }

    // Energy since construction or reset_energy(), in joules.
    double energy_in_J() const { return energy_in_J_; }
    double energy_lost_J() const { return energy_lost_J_; }
    double energy_stored_J() const;  // Σ C_i (T_i − T_i at the reset)
    void reset_energy();

    // The model as matrices (dx/dt = A x + b), for checks against an
    // independent solution.
    Eigen::MatrixXd a_matrix() const;
    Eigen::VectorXd b_vector() const;
    void fill_b_vector(Eigen::VectorXd& b) const;
    // True when advance() uses the eigen-decomposition (else the Van Loan path).
    bool modal() const;
    // How many times the model matrix was decomposed (changes of A).
    unsigned decompositions() const { return decompositions_; }

private:
    struct Node {
        std::string name;
        double capacity = 0;   // J/K; 0 for a follower
        double ambient_g = 0;  // W/K to ambient (masses)
        double power = 0;      // W (masses)
        int source = kAmbient; // followers
        double tau = 0;        // s (followers)
    };
    void check_node(int node, const char* what) const;
    void rebuild() const;         // A changed: decompose
    void rebuild_input() const;   // b changed: w = V⁻¹ b
    void advance_van_loan(double dt_s);

    std::vector<Node> nodes_;
    std::vector<double> x_;           // temperatures, degC
    std::vector<double> reference_;   // temperatures at the energy reset
    std::vector<std::vector<double>> g_;  // conductances between masses
    double ambient_ = 25.0;
    double time_s_ = 0;
    double energy_in_J_ = 0, energy_lost_J_ = 0;

    // Cached decomposition (mutable: rebuilt lazily).
    mutable bool model_dirty_ = true, input_dirty_ = true;
    mutable bool modal_ = true;
    mutable unsigned decompositions_ = 0;
    mutable Eigen::MatrixXd a_, v_, v_inv_;
    mutable Eigen::VectorXd b_, lambda_, w_;
    mutable Eigen::RowVectorXd loss_row_;  // g_ambᵀ V: loss rate from modal coordinates
    mutable double loss_offset_ = 0;       // Σ g_amb · T_amb

    // A heater's PWM alternates between two powers and two interval lengths:
    // the last two inputs (b -> w, loss offset) and the last two intervals'
    // modal coefficients are kept, keyed by the exact values they were
    // computed from, so a repeat costs a comparison and gives the same bits.
    struct InputMemo {
        Eigen::VectorXd b, w;
        double loss_offset = 0;
        double ambient_degC = 0;
        unsigned model = ~0u;  // decompositions_ when it was made
    };
    struct StepMemo {
        double dt_s = -1;
        unsigned model = ~0u;
        std::array<double, kMaxNodes> e{}, p1{}, p2{};
    };
    mutable std::array<InputMemo, 2> input_memo_;
    mutable std::array<StepMemo, 2> step_memo_;
    mutable unsigned input_memo_next_ = 0, step_memo_next_ = 0;
};

}  // namespace avrbench
