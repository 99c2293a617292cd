#include "parts/Electromagnet.hpp"

#include "parts/PartRegistry.hpp"

#include <cstdio>
#include <sstream>

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(Electromagnet, "electromagnet");
namespace {

// "a:b,c:d" -> {{a, b}, {c, d}}
std::vector<std::pair<double, double>> pairs(const std::string& text, const std::string& what) {
    std::vector<std::pair<double, double>> out;
    std::istringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        std::istringstream one(item);
        double a = 0, b = 0;
        char colon = 0;
        if (!(one >> a >> colon >> b) || colon != ':' || !(one >> std::ws).eof()) {
            throw BadInput(what + ": '" + item + "' is not x:y in mm");
        }
        out.emplace_back(a, b);
    }
    return out;
}

}  // namespace

std::vector<ParamSpec> Electromagnet::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "pieces", .type = PT::Text,
         .default_value = "-33:-67,-33:0,-33:67,33:-67,33:0,33:67,100:-67,100:0,100:67",
         .source = "seed 004 §4: the nine tack heads at x -3.3, 3.3, 10 cm and y -6.7, 0, 6.7 cm",
         .help = "x:y of each steel piece on the table, mm"},
        {.name = "table_z", .type = PT::Quantity, .dimension = D::Length, .default_value = "-340mm",
         .source = "seed 004 §4: the firmware descends to z = -34 cm to pick", .help = "the table's height (negative)",
         .min = -1000, .max = 1000},
        {.name = "pick_distance", .type = PT::Quantity, .dimension = D::Length, .default_value = "5mm",
         .source = "assumed: a small relay-coil magnet grips a tack head within a few mm",
         .help = "a resting piece this close to the effector is picked up"},
        {.name = "box", .type = PT::Text, .default_value = "-130:-70,-30:30",
         .source = "assumed: a 60 mm box around seed 004's drop point (-10, 0) cm",
         .help = "x_min:x_max,y_min:y_max of the box, mm"},
    };
}

Electromagnet::Electromagnet(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    const std::string where = "part '" + this->name() + "': ";
    table_z_mm_ = params.quantity("table_z") * 1e3;
    pick_distance_mm_ = params.quantity("pick_distance") * 1e3;
    for (const auto& [x, y] : pairs(params.text("pieces"), where + "pieces")) {
        pieces_.push_back({Eigen::Vector3d(x, y, table_z_mm_), false});
    }
    const auto box = pairs(params.text("box"), where + "box");
    if (box.size() != 2 || !(box[0].first < box[0].second) || !(box[1].first < box[1].second)) {
        throw BadInput(where + "box must be x_min:x_max,y_min:y_max with min < max");
    }
    box_[0] = box[0].first;
    box_[1] = box[0].second;
    box_[2] = box[1].first;
    box_[3] = box[1].second;
    coil_pin_ = add_pin("coil", TerminalRole::Input);
    require_port<Effector>("effector", true, "a delta_robot's effector", [this](Effector& effector) { connect_effector(effector); });
    sig_on_ = add_signal("energized", false, 0);
    sig_carried_ = add_signal("carried", true, 0);
    sig_in_box_ = add_signal("in_box", true, 0);
}

void Electromagnet::connect_effector(Effector& effector) {
    robot_ = &effector;
    robot_->on_move([this](const Eigen::Vector3d&) { update(); });
}

void Electromagnet::start() { publish(sig_in_box_, in_box()); }

void Electromagnet::on_input(std::size_t pin, bool level) {
    if (pin != coil_pin_ || level == energized_) return;
    energized_ = level;
    publish(sig_on_, energized_ ? 1 : 0);
    update();
}

unsigned Electromagnet::carried() const {
    unsigned n = 0;
    for (const auto& p : pieces_) n += p.carried ? 1 : 0;
    return n;
}

unsigned Electromagnet::in_box() const {
    unsigned n = 0;
    for (const auto& p : pieces_) {
        const auto& q = p.position_mm;
        n += !p.carried && q.x() >= box_[0] && q.x() <= box_[1] && q.y() >= box_[2] && q.y() <= box_[3] ? 1 : 0;
    }
    return n;
}

void Electromagnet::update() {
    const Eigen::Vector3d at = robot_->effector_mm();
    const unsigned carried_before = carried(), in_box_before = in_box();
    for (auto& p : pieces_) {
        if (p.carried) {
            if (energized_) {
                p.position_mm = at;
            } else {
                p.carried = false;  // falls straight down
                p.position_mm = Eigen::Vector3d(at.x(), at.y(), table_z_mm_);
            }
        } else if (energized_ && (p.position_mm - at).norm() <= pick_distance_mm_) {
            p.carried = true;
            p.position_mm = at;
        }
    }
    if (carried() != carried_before) publish(sig_carried_, carried());
    if (in_box() != in_box_before) publish(sig_in_box_, in_box());
}

std::string Electromagnet::summary() {
    char line[200];
    std::snprintf(line, sizeof line, "magnet     %s: %u of %zu pieces in the box, %u carried", name().c_str(), in_box(),
                  pieces_.size(), carried());
    return line;
}

}  // namespace avrbench
