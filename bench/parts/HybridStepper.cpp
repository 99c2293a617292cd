#include "parts/HybridStepper.hpp"

#include "parts/PartRegistry.hpp"

#include <cmath>
#include <numbers>
#include <cstdio>
#include <sstream>

#include "periph/adc/Adc.hpp"
#include "core/Errors.hpp"

namespace avrbench {

namespace {

// A bipolar (hybrid_stepper) or unipolar (unipolar_stepper) motor: one model,
// built with its winding layout.
PartType stepper_type(const std::string& type_name, bool unipolar) {
    PartType t;
    t.name = type_name;
    t.params = HybridStepper::param_specs(unipolar);
    t.presets = HybridStepper::presets();
    t.build = [unipolar](const std::string& name, Mcu& clock, const ParamValues& params) {
        return std::make_unique<HybridStepper>(name, clock, params, unipolar);
    };
    return t;
}

}  // namespace

REGISTER_PART_TYPE(stepper_type("hybrid_stepper", false));
REGISTER_PART_TYPE(stepper_type("unipolar_stepper", true));

const FindingKind HybridStepper::kMotorStall = FindingKind::declare("motor-stall", "a stepper motor's rotor lost synchronism with its excitation (lost steps)", Severity::Warning);
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
// A pole slip is counted when the rotor is more than this far (electrical)
// from the equilibrium of its present count: past pi the torque pulls it to
// the next equilibrium; the extra quarter turn keeps a rotor rocking on the
// unstable point from counting slips back and forth.
constexpr double kSlipThreshold = 1.25 * std::numbers::pi;

// "1,2" -> {1, 2}: a winding's plus and minus outputs on its bridge.
std::pair<int, int> output_pair(const std::string& text, const std::string& part, const std::string& param) {
    std::istringstream in(text);
    int plus = 0, minus = 0;
    char comma = 0;
    if (!(in >> plus >> comma >> minus) || comma != ',' || !(in >> std::ws).eof()) {
        throw part_error(part, param + " '" + text + "' is not two outputs 'plus,minus' (e.g. 1,2)");
    }
    return {plus, minus};
}

HybridStepperModel::Params model_params(const ParamValues& p, const std::string& name) {
    HybridStepperModel::Params m;
    const double step = p.quantity("step_angle");
    const double teeth = kTwoPi / (4 * step);
    if (step <= 0 || std::fabs(teeth - std::round(teeth)) > 1e-6) {
        throw part_error(name, "step_angle must be 90 degrees divided by a whole number of rotor teeth "
                       "(1.8deg: 50 teeth, 0.9deg: 100)");
    }
    m.rotor_teeth = static_cast<int>(std::lround(teeth));
    m.resistance_ohm = p.quantity("resistance");
    m.inductance_h = p.quantity("inductance");
    m.torque_constant_nm_per_a = p.quantity("torque_constant");
    m.detent_torque_nm = p.quantity("detent_torque");
    m.inertia_kg_m2 = p.quantity("rotor_inertia") + p.quantity("load_inertia");
    m.viscous_nm_s_per_rad = p.quantity("viscous_damping");
    m.coulomb_nm = p.quantity("coulomb_friction");
    m.load_torque_nm = p.quantity("load_torque");
    m.max_step_s = p.quantity("max_step");
    m.chopper_tau_s = p.quantity("chopper_tau");
    if (m.resistance_ohm <= 0 || m.inductance_h <= 0 || m.torque_constant_nm_per_a <= 0 || m.inertia_kg_m2 <= 0) {
        throw part_error(name, "resistance, inductance, torque_constant and inertia must be positive");
    }
    if (m.max_step_s <= 0 || m.max_step_s > 1e-3 || m.chopper_tau_s <= 0) {
        throw part_error(name, "max_step must be in (0, 1ms], chopper_tau positive");
    }
    return m;
}

std::vector<HybridStepperModel::Winding> windings_for(bool unipolar) {
    if (unipolar) return {{0, +1}, {1, +1}, {0, -1}, {1, -1}};  // A, B, C = A-, D = B-
    return {{0, +1}, {1, +1}};
}

}  // namespace

std::vector<ParamSpec> HybridStepper::param_specs(bool unipolar) {
    using PT = ParamType;
    using D = Dimension;
    std::vector<ParamSpec> specs = {
        {.name = "preset", .type = PT::Choice, .default_value = unipolar ? "unipolar-42-generic" : "sm-42byg011-25",
         .choices = {"sm-42byg011-25", "42byghw208", "unipolar-42-generic", "none"},
         .help = "motor data preset (see presets())"},
        {.name = "step_angle", .type = PT::Quantity, .dimension = D::Angle, .default_value = "1.8deg",
         .help = "full step angle (90 deg / rotor teeth)"},
        {.name = "resistance", .type = PT::Quantity, .dimension = D::Resistance,
         .help = "resistance per winding (half-winding: unipolar)"},
        {.name = "inductance", .type = PT::Quantity, .dimension = D::Inductance, .help = "inductance per winding"},
        {.name = "torque_constant", .type = PT::Quantity, .dimension = D::TorqueConstant,
         .help = "torque constant = back-EMF constant, per winding"},
        {.name = "detent_torque", .type = PT::Quantity, .dimension = D::Torque,
         .help = "detent torque amplitude (unexcited)"},
        {.name = "rotor_inertia", .type = PT::Quantity, .dimension = D::Inertia, .help = "rotor inertia"},
        {.name = "load_inertia", .type = PT::Quantity, .dimension = D::Inertia, .default_value = "0kg*m^2",
         .source = "no load unless given", .help = "inertia on the shaft"},
        {.name = "viscous_damping", .type = PT::Quantity, .dimension = D::RotaryDamping,
         .help = "viscous friction and iron losses"},
        {.name = "coulomb_friction", .type = PT::Quantity, .dimension = D::Torque,
         .help = "bearing (Coulomb) friction"},
        {.name = "load_torque", .type = PT::Quantity, .dimension = D::Torque, .default_value = "0N*m",
         .source = "no load unless given", .help = "constant load torque, acting against forward rotation"},
        {.name = "max_step", .type = PT::Quantity, .dimension = D::Time, .default_value = "20us",
         .source = "docs/MOTOR.md: figures unchanged from 2 us to 40 us", .help = "integration step bound (RK4)"},
        {.name = "sample_period", .type = PT::Quantity, .dimension = D::Time, .default_value = "100us",
         .help = "how often a moving motor is advanced without pin events (stall checks, traces)"},
        {.name = "chopper_tau", .type = PT::Quantity, .dimension = D::Time, .default_value = "20us",
         .source = "assumed: about one PWM period of an A4988/DRV8825 chopper",
         .help = "current tracking time constant (driver-driven)"},
        {.name = "release_delay", .type = PT::Quantity, .dimension = D::Time, .default_value = "1ms",
         .source = "assumed", .help = "a winding switched off alone counts as released (not chopped) after this long"},
        {.name = "stall_quiet", .type = PT::Quantity, .dimension = D::Time, .default_value = "100ms",
         .source = "assumed", .help = "a stall event ends after this long without another pole slip"},
        {.name = "hold_trace_period", .type = PT::Quantity, .dimension = D::Time, .default_value = "1ms",
         .source = "assumed: a 1 kHz view of a holding motor",
         .help = "once the command has stood still for stall_quiet, the signals are traced this often, not every tick"},
    };
    if (unipolar) {
        for (const char* c : {"a", "b", "c", "d"}) {
            specs.push_back({.name = std::string("coil_") + c, .type = PT::Integer,
                             .default_value = std::to_string(1 + (c[0] - 'a')),
                             .help = std::string("switch channel of half-winding ") + static_cast<char>(c[0] - 32),
                             .min = 1, .max = 8});
        }
        specs.push_back({.name = "supply", .type = PT::Quantity, .dimension = D::Voltage, .default_value = "12V",
                         .source = "assumed (seed 001 gives none)", .help = "supply at the centre taps"});
        specs.push_back({.name = "sense_resistor", .type = PT::Quantity, .dimension = D::Resistance,
                         .default_value = "0ohm", .source = "seed 001 §3.2: value absent",
                         .help = "R_sense per coil pair (A/C, B/D), 0 = none"});
    } else {
        specs.push_back({.name = "phase_a", .type = PT::Text, .default_value = "1,2",
                         .help = "bridge outputs of winding A: plus,minus (a step/dir driver: ignored)"});
        specs.push_back({.name = "phase_b", .type = PT::Text, .default_value = "3,4",
                         .help = "bridge outputs of winding B: plus,minus (a step/dir driver: ignored)"});
    }
    return specs;
}

const std::map<std::string, std::map<std::string, std::string>>& HybridStepper::presets() {
    static const std::map<std::string, std::map<std::string, std::string>> table = {
        // Mercury Motor SM-42BYG011-25, the motor of seed 003 (§1.7): 1.8 deg,
        // 12 V, 0.33 A, holding torque 0.23 N*m. R = 34 ohm, L = 46 mH and
        // Ke = 0.0763 V per electrical Hz from ponoor/step-series-support
        // configGenerator/motor_list.json; Km = Ke * 50 / (2 pi) = 0.607 N*m/A
        // (seed 003 digest §6.2). Rotor inertia, detent torque and friction
        // are not published: assumed, typical for a 34 mm NEMA 17 (digest
        // §6.2); docs/MOTOR.md shows how the validation depends on them.
        {"sm-42byg011-25",
         {{"step_angle", "1.8deg"}, {"resistance", "34ohm"}, {"inductance", "46mH"},
          {"torque_constant", "0.607N*m/A"}, {"detent_torque", "0.015N*m"}, {"rotor_inertia", "35g*cm^2"},
          {"viscous_damping", "5e-4N*m*s/rad"}, {"coulomb_friction", "0.002N*m"}}},
        // 42BYGHW208 (Wantai), the motors of seed 002 (§1): 1.8 deg, holding
        // torque 2.8 kg*cm = 0.275 N*m, J_M = 1.5e-6 kg*m^2 [seed 002, from the
        // datasheet]. 12 V / 0.4 A gives R = 30 ohm [rating]; L = 37 mH [the
        // Wantai data as quoted in public build notes]; Km = 0.275 / (sqrt(2) *
        // 0.4 A) = 0.49 N*m/A (holding torque with both phases at rated
        // current). Detent and friction assumed as above.
        {"42byghw208",
         {{"step_angle", "1.8deg"}, {"resistance", "30ohm"}, {"inductance", "37mH"},
          {"torque_constant", "0.49N*m/A"}, {"detent_torque", "0.012N*m"}, {"rotor_inertia", "15g*cm^2"},
          {"viscous_damping", "5e-4N*m*s/rad"}, {"coulomb_friction", "0.002N*m"}}},
        // A six-wire NEMA 17 for seed 001's unipolar drive boards, whose motor
        // the thesis does not name: assumed values per half-winding, low
        // enough in resistance that the board's current chopper has work.
        {"unipolar-42-generic",
         {{"step_angle", "1.8deg"}, {"resistance", "6.8ohm"}, {"inductance", "8mH"},
          {"torque_constant", "0.2N*m/A"}, {"detent_torque", "0.01N*m"}, {"rotor_inertia", "35g*cm^2"},
          {"viscous_damping", "5e-4N*m*s/rad"}, {"coulomb_friction", "0.002N*m"}}},
        {"none", {}},
    };
    return table;
}

HybridStepper::HybridStepper(std::string name, Mcu& clock, const ParamValues& params, bool unipolar)
    : Part(std::move(name), clock),
      unipolar_(unipolar),
      model_([&] {
          for (const char* needed : {"resistance", "inductance", "torque_constant", "detent_torque", "rotor_inertia",
                                     "viscous_damping", "coulomb_friction"}) {
              if (!params.has(needed)) {
                  throw part_error(this->name(), "give " + std::string(needed) + " (or a preset that has it)");
              }
          }
          return model_params(params, this->name());
      }(), windings_for(unipolar)) {
    seconds_per_cycle_ = 1.0 / clock.frequency_hz();
    auto cycles = [&](const char* param) {
        const double s = params.quantity(param);
        if (s <= 0) throw part_error(this->name(), std::string(param) + " must be positive");
        return static_cast<Cycle>(std::max(1.0, std::round(s * clock.frequency_hz())));
    };
    sample_cycles_ = cycles("sample_period");
    release_cycles_ = cycles("release_delay");
    stall_quiet_cycles_ = cycles("stall_quiet");
    hold_trace_cycles_ = cycles("hold_trace_period");
    if (unipolar_) {
        supply_v_ = params.quantity("supply");
        sense_ohm_ = params.quantity("sense_resistor");
        // Winding order A, B, C (= A-), D (= B-): the centre tap at the
        // supply, the half-winding's end on its switch channel.
        for (const char* coil : {"coil_a", "coil_b", "coil_c", "coil_d"}) {
            WindingTap tap;
            tap.minus = static_cast<int>(params.integer(coil));
            tap.supply_v = supply_v_;
            tap.series_ohm = sense_ohm_;
            taps_.push_back(tap);
        }
    } else {
        for (int phase = 0; phase < 2; ++phase) {
            const char* param = phase == 0 ? "phase_a" : "phase_b";
            const auto [plus, minus] = output_pair(params.text(param), this->name(), param);
            taps_.push_back({phase, plus, minus, 0, 0});
        }
    }
    require_port<DriveSource>("windings", true,
                              unipolar_ ? "a low_side_switch's windings" : "an l293d's or a step_dir_driver's windings",
                              [this](DriveSource& source) { connect_windings(source); });
    if (unipolar_) {
        for (int pair = 0; pair < 2; ++pair) {
            provide_analog(pair == 0 ? "sense_ac" : "sense_bd",
                           [this, pair](Cycle) {
                               sync();
                               return sense_voltage(pair);
                           },
                           pair == 0 ? "the A/C sense resistor's voltage" : "the B/D sense resistor's voltage");
        }
    }

    shaft_256_ = static_cast<std::int64_t>(std::llround(model_.electrical_angle() / (std::numbers::pi / 2) * 256.0));
    shaft_full_ = shaft_256_ >= 0 ? shaft_256_ / 256 : -((-shaft_256_ + 255) / 256);
    provide_port<ShaftMotion>("shaft", *this, "the rotor in full steps, for a linear_axis (a lead screw) to follow");
    sig_angle_ = add_signal("angle_deg", true);
    sig_command_ = add_signal("commanded_deg", true);
    sig_error_ = add_signal("following_error_deg", true);
    sig_speed_ = add_signal("speed_rpm", true);
    sig_ia_ = add_signal("current_a_A", true);
    sig_ib_ = add_signal("current_b_A", true);
    sig_lost_ = add_signal("lost_steps", true);
    sig_stalled_ = add_signal("stalled", false);
    if (unipolar_) {
        sig_sense_[0] = add_signal("sense_ac_V", true);
        sig_sense_[1] = add_signal("sense_bd_V", true);
    }
}

void HybridStepper::listen(DriveSource& source) {
    source.on_drive_change([this] { on_drive_change(); });
}

void HybridStepper::connect_windings(DriveSource& source) {
    for (const WindingTap& tap : taps_) {
        const std::string problem = source.tap_problem(tap);
        if (!problem.empty()) throw part_error(name(), problem);
    }
    source_ = &source;
    angle_from_source_ = source.commands_angle();
    listen(source);
}

std::string HybridStepper::summary() {
    sync();
    char line[200];
    std::snprintf(line, sizeof line, "motor      %s: at %.2f deg (commanded %.2f), %ld steps lost, %u stalls", name().c_str(),
                  angle_deg(), commanded_deg(), lost_steps(), stalls());
    return line;
}

void HybridStepper::start() {
    // A driver with its ENABLE unwired energizes the windings at power-on.
    on_drive_change();
}

void HybridStepper::sync() {
    const Cycle now = clock().cycle();
    if (now > last_cycle_) {
        model_.advance(static_cast<double>(now - last_cycle_) * seconds_per_cycle_);
        last_cycle_ = now;
    }
    check_slip();
}

double HybridStepper::angle_deg() const { return model_.angle() * 180.0 / std::numbers::pi; }

double HybridStepper::commanded_deg() const {
    // Before the first excitation the rotor is where it is told to be.
    if (!have_command_) return angle_deg();
    return command_e_ / model_.params().rotor_teeth * 180.0 / std::numbers::pi;
}

double HybridStepper::speed_rpm() const { return model_.speed() * 60.0 / kTwoPi; }

double HybridStepper::sense_voltage(int pair) const {
    if (!unipolar_) return 0;
    double amps = 0;
    for (std::size_t k = 0; k < model_.winding_count(); ++k) {
        if (static_cast<int>(k % 2) == pair && model_.drive(k).polarity != 0) amps += model_.current(k);
    }
    return amps * sense_ohm_;
}

void HybridStepper::refresh_drive() {
    for (std::size_t k = 0; k < taps_.size(); ++k) model_.set_drive(k, source_->winding_at(taps_[k]));
}

void HybridStepper::on_drive_change() {
    sync();
    refresh_drive();
    if (angle_from_source_) {
        if (source_->outputs_enabled()) set_command(source_->commanded_electrical_angle());
    } else {
        update_command_from_polarity();
    }
    check_slip();
    publish_all();
    arm_tick();
}

// The commanded angle of a coil-driven motor follows the excitation the
// firmware selects: per phase +1, -1 or 0 (not driven). A phase that goes to
// 0 while the other phase takes a new value at the same cycle (a step of a
// wave or full-step sequence) is released at once; one that goes to 0 alone
// (a current chopper, PWM on the enable pins, or the first half of a
// pin-by-pin update) keeps its last value until it has stayed off for
// `release_delay` or the other phase changes.
void HybridStepper::update_command_from_polarity() {
    const Cycle now = clock().cycle();
    int wanted[2] = {0, 0};
    for (std::size_t k = 0; k < model_.winding_count(); ++k) {
        const int phase = static_cast<int>(k % 2);
        const int sign = k < 2 ? 1 : -1;
        wanted[phase] += sign * model_.drive(k).polarity;
    }
    bool new_value = false;
    for (int p = 0; p < 2; ++p) {
        const int w = wanted[p] > 0 ? 1 : wanted[p] < 0 ? -1 : 0;
        if (w != 0) {
            release_pending_[p] = false;
            if (w != latched_[p]) {
                latched_[p] = w;
                new_value = true;
            }
        } else if (latched_[p] != 0 && !release_pending_[p]) {
            release_pending_[p] = true;
            release_since_[p] = now;
            const std::uint64_t generation = ++release_generation_[p];
            // Phase and generation in one word: with `this` the capture stays
            // within std::function's in-place buffer (16 bytes in libstdc++),
            // so a phase release allocates nothing.
            const std::uint64_t key = generation << 1 | static_cast<std::uint64_t>(p);
            clock().scheduler().at(now + release_cycles_, [this, key](Cycle) {
                const int phase = static_cast<int>(key & 1);
                if ((key >> 1) != release_generation_[phase] || !release_pending_[phase]) return;
                sync();
                // Phases switched off by the same update (or earlier) go together:
                // releasing one alone would swing the command half a step.
                const Cycle since = release_since_[phase];
                for (int q = 0; q < 2; ++q) {
                    if (release_pending_[q] && release_since_[q] <= since) {
                        release_pending_[q] = false;
                        latched_[q] = 0;
                    }
                }
                if (latched_[0] != 0 || latched_[1] != 0) {
                    set_command(std::atan2(latched_[1], latched_[0]));
                    check_slip();
                }
                publish_all();
            });
        }
    }
    if (new_value) last_on_change_ = now;
    for (int p = 0; p < 2; ++p) {
        if (release_pending_[p] && (new_value || release_since_[p] == last_on_change_)) {
            release_pending_[p] = false;
            latched_[p] = 0;
        }
    }
    if (latched_[0] != 0 || latched_[1] != 0) set_command(std::atan2(latched_[1], latched_[0]));
}

void HybridStepper::set_command(double electrical) {
    const Cycle now = clock().cycle();
    const double rotor_e = model_.electrical_angle();
    if (!have_command_) {
        // The first excitation: the rotor turns to the nearest equilibrium of it.
        if (angle_from_source_) {
            driver_offset_ = kTwoPi * std::round((rotor_e - electrical) / kTwoPi);
            command_e_ = electrical + driver_offset_;
        } else {
            command_e_ = electrical + kTwoPi * std::round((rotor_e - electrical) / kTwoPi);
        }
        have_command_ = true;
        last_command_change_ = prev_command_change_ = now;
        return;
    }
    double next;
    if (angle_from_source_) {
        next = electrical + driver_offset_;
    } else {
        next = command_e_ + std::remainder(electrical - command_e_, kTwoPi);
    }
    if (next == command_e_) return;
    if (now == last_command_change_) {
        // Several pins of one update (a 74HC595 latching its outputs one by one).
        last_command_delta_e_ += next - command_e_;
    } else {
        last_command_delta_e_ = next - command_e_;
        prev_command_change_ = last_command_change_;
        last_command_change_ = now;
    }
    command_e_ = next;
    // A coil-driven motor's step is a new excitation (a step/dir driver
    // notes its own STEP pulses): the bench's idle detection hears it.
    if (!angle_from_source_) note_activity();
}

void HybridStepper::check_slip() {
    if (!have_command_) return;
    const double error = command_e_ - model_.electrical_angle();
    const long before = slip_count_;
    while (error - kTwoPi * static_cast<double>(slip_count_) > kSlipThreshold) ++slip_count_;
    while (error - kTwoPi * static_cast<double>(slip_count_) < -kSlipThreshold) --slip_count_;
    if (slip_count_ == before) return;
    slips_total_ += static_cast<std::uint64_t>(std::labs(slip_count_ - before));
    const Cycle now = clock().cycle();
    const bool new_event = !in_stall_ || now - last_slip_ > stall_quiet_cycles_;
    in_stall_ = true;
    last_slip_ = now;
    if (!new_event) return;
    ++stalls_;
    StallEvent ev;
    ev.cycle = now;
    ev.commanded_deg = commanded_deg();
    ev.rotor_deg = angle_deg();
    const Cycle interval = last_command_change_ - prev_command_change_;
    ev.commanded_rpm = interval == 0 ? 0
                                     : std::fabs(last_command_delta_e_) / model_.params().rotor_teeth /
                                           (static_cast<double>(interval) * seconds_per_cycle_) * 60.0 / kTwoPi;
    ev.lost_steps = lost_steps();
    char detail[240];
    std::snprintf(detail, sizeof detail,
                  "rotor lost synchronism with its excitation (excitation at %.0f rpm): rotor %.1f deg, commanded "
                  "%.1f deg, %ld full steps lost so far",
                  ev.commanded_rpm, ev.rotor_deg, ev.commanded_deg, ev.lost_steps);
    report(HybridStepper::kMotorStall, detail);
    for (auto& fn : stall_listeners_) fn(ev);
}

void HybridStepper::arm_tick() {
    if (tick_armed_) return;
    tick_armed_ = true;
    clock().scheduler().at(clock().cycle() + sample_cycles_, [this](Cycle) { on_tick(); });
}

void HybridStepper::on_tick() {
    tick_armed_ = false;
    sync();
    if (in_stall_ && clock().cycle() - last_slip_ > stall_quiet_cycles_) in_stall_ = false;
    publish_all();
    if (!model_.settled() || in_stall_) arm_tick();
}

std::string HybridStepper::motion_summary() const {
    char text[80];
    std::snprintf(text, sizeof text, "%llu full steps of the rotor", static_cast<unsigned long long>(shaft_steps_));
    return text;
}

void HybridStepper::update_shaft() {
    // Electrical angle / (pi/2) full steps; the shaft in 1/256 of one.
    const auto now_256 = static_cast<std::int64_t>(std::llround(model_.electrical_angle() / (std::numbers::pi / 2) * 256.0));
    if (now_256 == shaft_256_) return;
    const std::int64_t delta = now_256 - shaft_256_;
    shaft_256_ = now_256;
    const std::int64_t full = now_256 >= 0 ? now_256 / 256 : -((-now_256 + 255) / 256);
    shaft_steps_ += static_cast<std::uint64_t>(full > shaft_full_ ? full - shaft_full_ : shaft_full_ - full);
    shaft_full_ = full;
    for (auto& fn : shaft_listeners_) fn(static_cast<int>(delta));
}

void HybridStepper::publish_all() {
    update_shaft();
    // A motor holding its position under a chopping driver never settles: its
    // currents ripple and the rotor trembles by hundredths of a degree. While
    // the command stands still its signals are traced every
    // `hold_trace_period`, not every tick (a minute of holding would
    // otherwise be tens of millions of trace events); a new command, a stall
    // or a stall's end is traced at once.
    const Cycle now = clock().cycle();
    const double command = commanded_deg();
    if (command != last_traced_command_ || in_stall_ != last_traced_stall_) last_traced_change_ = now;
    const bool holding = now - last_traced_change_ > stall_quiet_cycles_;
    if (holding && traced_once_ && now - last_trace_ < hold_trace_cycles_) return;
    traced_once_ = true;
    last_trace_ = now;
    last_traced_command_ = command;
    last_traced_stall_ = in_stall_;
    publish(sig_angle_, angle_deg());
    publish(sig_command_, commanded_deg());
    publish(sig_error_, following_error_deg());
    publish(sig_speed_, speed_rpm());
    publish(sig_ia_, model_.phase_current(0));
    publish(sig_ib_, model_.phase_current(1));
    publish(sig_lost_, static_cast<double>(lost_steps()));
    publish(sig_stalled_, in_stall_ ? 1 : 0);
    if (unipolar_) {
        publish(sig_sense_[0], sense_voltage(0));
        publish(sig_sense_[1], sense_voltage(1));
    }
}

}  // namespace avrbench
