#include "fwconfig/BoardFromConfig.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "core/Errors.hpp"
#include "core/Units.hpp"

namespace avrbench {

namespace {

constexpr const char* kAxes[3] = {"x", "y", "z"};

std::string num(double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.10g", v);
    return b;
}
std::string mm(double v) { return num(v) + "mm"; }

// A part declared again: the base's parameters in order, some replaced.
struct PartOut {
    std::string name, type;
    std::vector<std::pair<std::string, std::string>> params;
    std::vector<std::string> comments;

    void set(const std::string& key, const std::string& value) {
        for (auto& [k, v] : params) {
            if (k == key) {
                v = value;
                return;
            }
        }
        params.emplace_back(key, value);
    }
    void erase(const std::string& key) {
        for (auto it = params.begin(); it != params.end(); ++it) {
            if (it->first == key) {
                params.erase(it);
                return;
            }
        }
    }
    std::string get(const std::string& key) const {
        for (const auto& [k, v] : params) {
            if (k == key) return v;
        }
        return {};
    }
};

std::string yaml_value(const std::string& v) {
    if (v.empty() || v.find_first_of(":{}[],#&*!|>'\"%@`") != std::string::npos || v == "yes" || v == "no") {
        std::string q = "\"";
        for (const char c : v) q += c == '"' ? std::string("\\\"") : std::string(1, c);
        return q + "\"";
    }
    return v;
}

class Writer {
public:
    Writer(const MachineConfig& config, const BoardSpec& base) : config_(config), base_(base) {}

    PartOut& part(const std::string& name) {
        for (auto& p : parts_) {
            if (p.name == name) return p;
        }
        const PartDecl* decl = base_.find_part(name);
        PartOut p{name, decl ? decl->type : "", {}, {}};
        if (decl != nullptr) {
            for (const auto& raw : decl->params) p.params.emplace_back(raw.name, raw.value);
        }
        parts_.push_back(std::move(p));
        return parts_.back();
    }
    bool has(const std::string& name) const { return base_.find_part(name) != nullptr; }
    // A parameter of the base's part as written, without declaring the part again.
    std::string base_param(const std::string& name, const std::string& key) const {
        for (const auto& p : parts_) {
            if (p.name == name) return p.get(key);
        }
        const PartDecl* decl = base_.find_part(name);
        if (decl == nullptr) return {};
        for (const auto& raw : decl->params) {
            if (raw.name == key) return raw.value;
        }
        return {};
    }
    std::string type_of(const std::string& name) const {
        const PartDecl* d = base_.find_part(name);
        return d ? d->type : "";
    }
    // The base's limit switches on an axis: parts of type limit_switch named "<axis>_...".
    std::vector<std::string> switches_of(const std::string& axis) const {
        std::vector<std::string> out;
        for (const auto& p : base_.parts) {
            if (p.type == "limit_switch" && p.name.rfind(axis + "_", 0) == 0) out.push_back(p.name);
        }
        return out;
    }
    const LabelDecl* label(const std::string& name) const {
        for (const auto& l : base_.labels) {
            if (l.name == name) return &l;
        }
        return nullptr;
    }
    const NetDecl* net_with(const std::string& endpoint) const {
        for (const auto& n : base_.nets) {
            for (const auto& e : n.endpoints) {
                if (e.text() == endpoint) return &n;
            }
        }
        return nullptr;
    }
    void net(const std::string& name, const std::vector<std::string>& endpoints, const std::string& comment) {
        nets_.push_back({name, endpoints, comment});
    }
    void not_mapped(const std::string& what) { not_mapped_.push_back(what); }

    std::string text(const std::string& header) const {
        std::ostringstream out;
        out << header;
        out << "parts:\n";
        for (const auto& p : parts_) {
            for (const auto& c : p.comments) out << "  # " << c << "\n";
            out << "  " << p.name << ": {type: " << p.type;
            for (const auto& [k, v] : p.params) out << ", " << k << ": " << yaml_value(v);
            out << "}\n";
        }
        if (!nets_.empty()) {
            out << "\nnets:\n";
            for (const auto& n : nets_) {
                if (!n.comment.empty()) out << "  # " << n.comment << "\n";
                out << "  " << n.name << ": [";
                for (std::size_t i = 0; i < n.endpoints.size(); ++i) out << (i ? ", " : "") << n.endpoints[i];
                out << "]\n";
            }
        }
        std::vector<std::string> all = config_.not_mapped;
        all.insert(all.end(), not_mapped_.begin(), not_mapped_.end());
        if (!all.empty()) {
            out << "\n# Not mapped:\n";
            for (const auto& n : all) out << "#   " << n << "\n";
        }
        return out.str();
    }

private:
    struct NetOut {
        std::string name;
        std::vector<std::string> endpoints;
        std::string comment;
    };
    const MachineConfig& config_;
    const BoardSpec& base_;
    std::vector<PartOut> parts_;
    std::vector<NetOut> nets_;
    std::vector<std::string> not_mapped_;
};

// A switch's logic as a limit_switch's contact, supply side and pull: with
// the MCU's pull-up a mechanical switch to GND (normally closed when it
// reads high triggered, open otherwise); without one a switch that drives
// both levels (an optical endstop), high or low when triggered.
void set_logic(PartOut& sw, const EndstopLogic& logic) {
    if (logic.pull_up) {
        sw.set("contact", logic.triggered_high ? "NC" : "NO");
        sw.set("switched_to", "gnd");
        sw.set("pull", "internal_up");
    } else {
        sw.set("contact", logic.triggered_high ? "NO" : "NC");
        sw.set("switched_to", "vcc");
        sw.set("pull", "push_pull");
    }
}

double length_mm(const std::string& value, const std::string& what) {
    return parse_quantity(value, Dimension::Length, what) * 1e3;
}

}  // namespace

std::string board_from_config(const MachineConfig& config, const BoardFromConfigOptions& options) {
    std::string base_name = options.base;
    std::string base_source = "--base " + options.base;
    if (base_name.empty()) {
        if (!config.base_board) {
            throw BadInput((config.base_unknown.empty() ? std::string("no board named") : config.base_unknown) +
                           ": give the board to extend with --base (avrbench boards lists them)");
        }
        base_name = config.base_board->value;
        base_source = config.base_board->source;
    }
    const BoardSpec base = load_board_file(base_name);
    Writer w(config, base);
    const bool grbl = config.firmware.rfind("grbl", 0) == 0;
    const std::string oracle = [&] {
        for (const auto& p : base.parts) {
            if (p.type == "motion_oracle") return p.name;
        }
        return std::string();
    }();

    for (int k = 0; k < 3; ++k) {
        const AxisConfig& a = config.axes[k];
        const std::string axis = kAxes[k];
        const std::string driver = axis + "_driver";
        if (!w.has(axis) || !w.has(driver)) {
            if (a.steps_per_mm) w.not_mapped("axis " + axis + ": the board has no '" + axis + "' and '" + driver + "' parts");
            continue;
        }
        PartOut& d = w.part(driver);
        if (a.dir_high_is_plus) {
            d.set("forward_dir", a.dir_high_is_plus->value ? "high" : "low");
            d.comments.push_back("DIR " + std::string(a.dir_high_is_plus->value ? "high" : "low") + " for + : " + a.dir_high_is_plus->source);
        }
        if (a.enable_high) {
            if (d.type == "step_dir_driver") {
                d.set("enable_active", a.enable_high->value ? "high" : "low");
                d.comments.push_back("enable active " + std::string(a.enable_high->value ? "high" : "low") + ": " + a.enable_high->source);
            } else if (a.enable_high->value) {
                w.not_mapped(a.enable_high->source + ": the " + d.type + "'s enable is active low");
            }
        }
        if (a.microsteps) {
            d.set("microsteps", std::to_string(a.microsteps->value));
            d.comments.push_back("microsteps: " + a.microsteps->source);
        }
        if (a.stall_sgt && d.type == "tmc2130") {
            d.set("stall_sgt", std::to_string(a.stall_sgt->value));
            d.comments.push_back("stallGuard tuning: " + a.stall_sgt->source);
        }

        PartOut& ax = w.part(axis);
        if (a.steps_per_mm) {
            ax.set("steps_per_mm", num(a.steps_per_mm->value));
            ax.comments.push_back("steps/mm: " + a.steps_per_mm->source);
        }
        // The switches the base has on this axis and how far inside their end they sit.
        const auto switches = w.switches_of(axis);
        double inset = 0;
        for (const auto& s : switches) {
            const std::string side = w.base_param(s, "side");
            const std::string pos = w.base_param(s, "position");
            if (pos.empty()) continue;
            const double at = length_mm(pos, s + ".position");
            const double travel = length_mm(ax.get("travel"), axis + ".travel");
            inset = side == "max" ? travel - at : at;
        }
        // A real switch trips before the hard stop: at least 2 mm of room past it
        // (a homing cycle overshoots the trip point by a step or more).
        if (a.min_switch || a.max_switch) inset = std::max(inset, 2.0);
        double travel = length_mm(ax.get("travel"), axis + ".travel");
        // The travel follows the firmware's range where switches bound it; an
        // axis homed without one (against its frame) keeps the board's.
        if (a.min_mm && a.max_mm && a.max_mm->value > a.min_mm->value && (a.min_switch || a.max_switch)) {
            travel = a.max_mm->value - a.min_mm->value + 2 * inset;
            ax.set("travel", mm(travel));
            ax.set("start_position", mm(travel / 2));
            const std::string sources =
                a.min_mm->source == a.max_mm->source ? a.min_mm->source : a.min_mm->source + "; " + a.max_mm->source;
            ax.comments.push_back("positions " + num(a.min_mm->value) + " .. " + num(a.max_mm->value) + " mm (" + sources +
                                  "), switches " + num(inset) +
                                  " mm inside the ends: travel " + num(travel) + " mm, starting mid-travel");
        }
        // Switches: the configuration's at their ends, with its logic.
        for (const bool max_end : {false, true}) {
            const auto& logic = max_end ? a.max_switch : a.min_switch;
            if (!logic) continue;
            std::string name;
            for (const auto& s : switches) {
                if ((w.base_param(s, "side") == "max") == max_end) name = s;
            }
            // The only switch of a board without an input for the other end (a
            // CNC shield's shared limit pin) goes to the end the firmware uses.
            if (name.empty() && switches.size() == 1 && !(a.min_switch && a.max_switch) &&
                w.label(axis + (max_end ? "_max" : "_min")) == nullptr) {
                name = switches[0];
            }
            if (name.empty()) {
                // A second switch on the pin the board labels for it (RAMPS' X_MAX D2 = PE4).
                const LabelDecl* pin = w.label(axis + (max_end ? "_max" : "_min"));
                const NetDecl* carriage = w.net_with(axis + ".carriage");
                if (pin == nullptr || carriage == nullptr) {
                    w.not_mapped(logic->source + ": the board has no " + (max_end ? "max" : "min") + " switch input on " + axis);
                    continue;
                }
                name = axis + (max_end ? "_max_switch" : "_min_switch");
                PartOut& sw = w.part(name);
                sw.type = "limit_switch";
                std::vector<std::string> coupled;
                for (const auto& e : carriage->endpoints) coupled.push_back(e.text());
                coupled.push_back(name + ".axis");
                w.net(carriage->name, coupled, "the carriage also trips " + name);
                w.net(name, {pin->endpoint.text(), name + ".out"}, name + " on the board's " + pin->name + " input");
            }
            PartOut& sw = w.part(name);
            sw.set("side", max_end ? "max" : "min");
            sw.set("position", mm(max_end ? travel - inset : inset));
            set_logic(sw, logic->value);
            sw.comments.push_back(std::string(max_end ? "max" : "min") + " switch, " +
                                  (logic->value.triggered_high ? "triggered high" : "triggered low") +
                                  (logic->value.pull_up ? " with the MCU's pull-up" : " without a pull-up (it drives both levels)") +
                                  ": " + logic->source);
        }
        // The oracle's frame: where homing puts the firmware's 0 on the carriage, and its software endstops.
        if (!oracle.empty() && !grbl && config.homing_not_judged) {
            w.part(oracle).erase("home_" + axis);
        } else if (!oracle.empty() && !grbl && a.min_mm && a.max_mm && a.home_dir) {
            PartOut& o = w.part(oracle);
            const bool to_max = a.home_dir->value > 0;
            const double home = to_max ? travel - inset - a.max_mm->value : inset - a.min_mm->value;
            o.set("home_" + axis, mm(home));
            o.comments.push_back(axis + " homes to its " + (to_max ? "max" : "min") + " switch (" + a.home_dir->source +
                                 ") and calls it " + num(to_max ? a.max_mm->value : a.min_mm->value) + ": its 0 is at " +
                                 num(home) + " mm on the carriage");
            if (config.soft_min && config.soft_min->value) o.set("soft_min_" + axis, mm(a.min_mm->value));
            if (config.soft_max && config.soft_max->value) o.set("soft_max_" + axis, mm(a.max_mm->value));
        }
    }
    if (!oracle.empty() && !grbl) {
        PartOut& o = w.part(oracle);
        if (config.homing_not_judged) {
            o.comments.push_back("no home: " + *config.homing_not_judged + ", so G28 ends the judging");
            o.set("no_home_because", *config.homing_not_judged);
        }
        if (config.soft_min && config.soft_min->value) o.comments.push_back("software endstops: " + config.soft_min->source);
        if (config.soft_max && config.soft_max->value && (!config.soft_min || config.soft_max->source != config.soft_min->source)) {
            o.comments.push_back("software endstops: " + config.soft_max->source);
        }
    }
    if (config.e_steps_per_mm) {
        if (w.has("hotend") && w.type_of("hotend") == "thermal_plant") {
            PartOut& h = w.part("hotend");
            h.set("filament_steps_per_mm", num(config.e_steps_per_mm->value));
            h.comments.push_back("E steps/mm: " + config.e_steps_per_mm->source);
        } else {
            w.not_mapped(config.e_steps_per_mm->source + ": the board has no hot end fed by E");
        }
    }
    for (const auto& [slot, name] : {std::pair{&config.hotend_thermistor, "hotend_thermistor"}, std::pair{&config.bed_thermistor, "bed_thermistor"}}) {
        if (!*slot) continue;
        if (!w.has(name)) {
            w.not_mapped((*slot)->source + ": the board has no " + name);
            continue;
        }
        PartOut& t = w.part(name);
        if ((*slot)->value == "ad595") {
            // The same ports (body, out) as the thermistor it replaces, so the base's nets hold.
            t.type = "thermocouple_amplifier";
            t.params.clear();
            t.set("preset", "ad595");
            t.comments.push_back("a thermocouple on an AD595: " + (*slot)->source);
        } else {
            t.set("preset", (*slot)->value);
            t.comments.push_back("thermistor: " + (*slot)->source);
        }
    }

    std::ostringstream header;
    header << "# Made by `avrbench board from-config` from " << config.firmware << "'s configuration:\n";
    for (const auto& in : options.inputs) header << "#   " << in << "\n";
    header << "# on " << base_name << " (" << base_source << "). Each part below replaces the base's\n"
           << "# part of that name whole; the comments say which lines gave its values.\n";
    header << "board: " << options.name << "\n";
    header << "description: " << yaml_value(config.firmware + "'s configuration on " + base_name) << "\n";
    header << "extends: " << base_name << "\n\n";
    return w.text(header.str());
}

}  // namespace avrbench
