// An electromagnet on a mechanism's effector (port `effector`), picking up
// small steel pieces from a table and dropping them: seed 004's tack heads.
// While the coil is energized, every piece resting within `pick_distance` of
// the effector is attached and moves with it; when the coil is switched off
// the attached pieces fall straight down onto the table. Traced: how many are
// carried and how many rest inside the box.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "parts/Effector.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {


class Electromagnet final : public Part {
public:
    static std::vector<ParamSpec> param_specs();

    Electromagnet(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "electromagnet"; }
    void start() override;
    std::string summary() override;

    struct Piece {
        Eigen::Vector3d position_mm;
        bool carried = false;
    };
    const std::vector<Piece>& pieces() const { return pieces_; }
    bool energized() const { return energized_; }
    unsigned carried() const;
    unsigned in_box() const;

private:
    void connect_effector(Effector& effector);
    void on_input(std::size_t pin, bool level) override;
    void update();

    std::size_t coil_pin_;
    Effector* robot_ = nullptr;
    std::vector<Piece> pieces_;
    double table_z_mm_, pick_distance_mm_;
    double box_[4];  // x min, x max, y min, y max (mm)
    bool energized_ = false;
    std::size_t sig_on_, sig_carried_, sig_in_box_;
};

}  // namespace avrbench
