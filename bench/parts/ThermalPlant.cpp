#include "parts/ThermalPlant.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/Errors.hpp"
#include "parts/ShaftMotion.hpp"

namespace avrbench {

REGISTER_PART(ThermalPlant, "thermal_plant");

const FindingKind ThermalPlant::kHeatingUnmonitored = FindingKind::declare(
    "heating-unmonitored",
    "a heater heated a body whose thermistor the firmware did not read for `unmonitored_after` (no temperature control, "
    "no thermal-runaway protection)",
    Severity::Warning);
const FindingKind ThermalPlant::kReadyWhileCold = FindingKind::declare(
    "ready-while-cold", "the firmware's \"at temperature\" line (the plant's `ready` pin) was high at a sample with the "
    "sensor below `ready_min`", Severity::Warning);
const FindingKind ThermalPlant::kOverheat = FindingKind::declare("overheat", "a thermal plant passed its safe maximum temperature", Severity::Warning);

std::vector<ParamSpec> ThermalPlant::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "preset", .type = PT::Choice, .default_value = "e3d_v6",
         .choices = {"e3d_v6", "heated_bed", "custom"},
         .help = "e3d_v6: Marlin's MPC defaults (40 W hot end); heated_bed: 220 mm PCB bed with glass; custom: give every value"},
        {.name = "ambient", .type = PT::Quantity, .dimension = D::Temperature, .default_value = "25degC",
         .source = "assumed: room temperature", .help = "air temperature"},
        {.name = "initial", .type = PT::Quantity, .dimension = D::Temperature,
         .help = "temperature of every node at power-on (default: ambient)"},
        {.name = "heat_capacity", .type = PT::Quantity, .dimension = D::HeatCapacity, .source = "preset",
         .help = "heat capacity of the block", .min = 1e-3},  // a thermistor bead alone is ~10 mJ/K
        {.name = "ambient_conductance", .type = PT::Quantity, .dimension = D::ThermalConductance, .source = "preset",
         .help = "block to ambient, fan off"},
        {.name = "ambient_conductance_fan", .type = PT::Quantity, .dimension = D::ThermalConductance,
         .source = "preset", .help = "block to ambient with the fan at full speed (default: as fan off)"},
        {.name = "surface_heat_capacity", .type = PT::Quantity, .dimension = D::HeatCapacity, .default_value = "0J/K",
         .help = "second mass joined to the block (0: none)"},
        {.name = "surface_conductance", .type = PT::Quantity, .dimension = D::ThermalConductance,
         .default_value = "0W/K", .help = "block to surface"},
        {.name = "surface_ambient_conductance", .type = PT::Quantity, .dimension = D::ThermalConductance,
         .default_value = "0W/K", .help = "surface to ambient"},
        {.name = "sensor_time_constant", .type = PT::Quantity, .dimension = D::Time, .source = "preset",
         .help = "thermistor bead lag behind the block (0: reads the block itself)"},
        {.name = "filament_steps_per_mm", .type = PT::Quantity, .default_value = "500",
         .source = "Marlin Configuration.h DEFAULT_AXIS_STEPS_PER_UNIT E = 500 (at the driver's configured microsteps)",
         .help = "driver steps per mm of filament", .min = 1e-3, .max = 1e6},
        {.name = "filament_J_per_K_per_mm", .type = PT::Quantity, .default_value = "0.0056",
         .source = "Marlin Configuration.h FILAMENT_HEAT_CAPACITY_PERMM 5.6e-3 J/K/mm (1.75 mm PLA)",
         .help = "heat to warm 1 mm of filament by 1 K", .min = 0, .max = 10},
        {.name = "max_temperature", .type = PT::Quantity, .dimension = D::Temperature, .source = "preset",
         .help = "an overheat finding when the block passes it"},
        {.name = "unmonitored_after", .type = PT::Quantity, .dimension = D::Time, .default_value = "5s",
         .source = "assumed: a firmware that regulates reads its sensor far more often (Marlin's temperature ISR "
                   "about every millisecond, Teacup's every 10 ms); 5 s leaves room for a slow loop",
         .help = "heating-unmonitored when a heater heats this long with no read of a thermistor on the body",
         .min = 1e-3, .max = 3600},
        {.name = "ready_min", .type = PT::Quantity, .dimension = D::Temperature, .default_value = "150degC",
         .source = "assumed: below any filament's printing temperature (PLA from about 180 degC)",
         .help = "ready-while-cold when the `ready` pin (the firmware's TEMP_OK, if wired) is high below this"},
        {.name = "sample_interval", .type = PT::Quantity, .dimension = D::Time, .default_value = "100ms",
         .source = "assumed", .help = "period of the temperature traces and of the filament-feed update"},
    };
}

const std::map<std::string, std::map<std::string, std::string>>& ThermalPlant::presets() {
    static const std::map<std::string, std::map<std::string, std::string>> table = {
        // Marlin 2.1 Configuration.h, MPCTEMP section, "Measured physical
        // constants from M306": MPC_BLOCK_HEAT_CAPACITY 16.7 J/K,
        // MPC_SENSOR_RESPONSIVENESS 0.22 K/s per K (tau = 1/0.22 s),
        // MPC_AMBIENT_XFER_COEFF 0.068 W/K, MPC_AMBIENT_XFER_COEFF_FAN255
        // 0.097 W/K, for a 40 W cartridge hot end (MPC_HEATER_POWER 40).
        // max_temperature: assumed 285 degC (an all-metal V6-class hot end).
        {"e3d_v6", {{"heat_capacity", "16.7J/K"}, {"ambient_conductance", "0.068W/K"},
                    {"ambient_conductance_fan", "0.097W/K"}, {"sensor_time_constant", "4.5454545s"},
                    {"max_temperature", "285degC"}}},
        // A 220 x 220 mm PCB bed (FR4, 1.6 mm) under 3 mm borosilicate glass;
        // every value derived in docs/THERMAL.md from material data
        // (FR4: 1850 kg/m3, 1100 J/(kg K), assumed; glass: Schott Borofloat 33
        // datasheet 2230 kg/m3, 830 J/(kg K)) and assumed film coefficients.
        {"heated_bed", {{"heat_capacity", "158J/K"}, {"ambient_conductance", "0.44W/K"},
                        {"ambient_conductance_fan", "0.44W/K"}, {"surface_heat_capacity", "269J/K"},
                        {"surface_conductance", "10W/K"}, {"surface_ambient_conductance", "0.65W/K"},
                        {"sensor_time_constant", "2s"}, {"max_temperature", "130degC"}}},
        {"custom", {}},
    };
    return table;
}

ThermalPlant::ThermalPlant(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    auto need = [&](const char* param) {
        if (!params.has(param)) {
            throw part_error(this->name(), "a " + params.text("preset") + " plant needs " + param);
        }
        return params.quantity(param);
    };
    const double ambient = params.quantity("ambient");
    const double initial = params.has("initial") ? params.quantity("initial") : ambient;
    const double capacity = need("heat_capacity");
    g_ambient_ = need("ambient_conductance");
    g_ambient_fan_ = params.has("ambient_conductance_fan") ? params.quantity("ambient_conductance_fan") : g_ambient_;
    const double tau = need("sensor_time_constant");
    max_degC_ = params.has("max_temperature") ? params.quantity("max_temperature") : 1e9;
    filament_J_per_K_mm_ = params.quantity("filament_J_per_K_per_mm");
    filament_steps_per_mm_ = params.quantity("filament_steps_per_mm");
    if (!(capacity > 0)) throw part_error(this->name(), "heat_capacity must be positive");
    if (g_ambient_ < 0 || g_ambient_fan_ < 0 || tau < 0 || filament_J_per_K_mm_ < 0 || !(filament_steps_per_mm_ > 0)) {
        throw part_error(this->name(), "conductances, time constants and filament values must not be negative");
    }
    network_.set_ambient(ambient);
    block_ = network_.add_mass("block", capacity, initial);
    const double surface_capacity = params.quantity("surface_heat_capacity");
    if (surface_capacity > 0) {
        surface_ = network_.add_mass("surface", surface_capacity, initial);
        network_.set_conductance(block_, surface_, params.quantity("surface_conductance"));
        network_.set_ambient_conductance(surface_, params.quantity("surface_ambient_conductance"));
    }
    sensor_ = tau > 0 ? network_.add_follower("sensor", block_, tau, initial) : block_;
    apply_conductance();
    network_.reset_energy();

    const double interval = params.quantity("sample_interval");
    if (!(interval > 0)) throw part_error(this->name(), "sample_interval must be positive");
    sample_cycles_ = std::max<Cycle>(1, clock.cycles_from_seconds(interval));
    unmonitored_cycles_ = clock.cycles_from_seconds(params.quantity("unmonitored_after"));
    ready_min_degC_ = params.quantity("ready_min");
    ready_pin_ = add_pin("ready", TerminalRole::Input);

    sig_block_ = add_signal({"block_degC", true, "degC", "temperature", ""}, initial);
    sig_sensor_ = add_signal({"sensor_degC", true, "degC", "sensor-temperature", ""}, initial);
    if (surface_ >= 0) sig_surface_ = add_signal("surface_degC", true, initial);
    sig_fan_ = add_signal("fan_speed", true, 0);
    provide_port<ThermalBody>("body", *this, "the block heaters heat, thermistors read and fans cool");
    require_port<ShaftMotion>("filament", false, "the extruder's step_dir_driver steps: they feed cold filament into the block",
                              [this](ShaftMotion& feed) { connect_filament(feed); });
}

void ThermalPlant::connect_filament(ShaftMotion& feed) {
    filament_driver_ = &feed;
    filament_driver_->on_step([this](int delta_256) { feed_256_ += delta_256; });
}

std::string ThermalPlant::summary() {
    char line[200];
    const double block = block_degC(), sensor = sensor_degC();
    if (diverged_ || !std::isfinite(block) || !std::isfinite(sensor)) {
        std::snprintf(line, sizeof line, "thermal    %s: the model's temperatures are not finite numbers (see findings)", name().c_str());
        return line;
    }
    std::snprintf(line, sizeof line, "thermal    %s: block %.2f degC, sensor %.2f degC, heater %.1f W now", name().c_str(), block,
                  sensor, heater_power_W());
    return line;
}

void ThermalPlant::start() {
    last_cycle_ = clock().cycle();
    last_sensor_read_ = last_cycle_;
    clock().scheduler().at(last_cycle_ + sample_cycles_, [this](Cycle c) { on_sample(c); });
}

void ThermalPlant::advance() {
    const Cycle now = clock().cycle();
    if (now > last_cycle_) {
        network_.advance(static_cast<double>(now - last_cycle_) / clock().frequency_hz());
        last_cycle_ = now;
    }
    const double block = network_.temperature(block_);
    if (!std::isfinite(block)) {
        // The heating-rate check at construction keeps the model finite; should
        // parameters still combine past it, that is a finding (this code runs
        // inside simavr's callbacks, where no exception may pass), and the
        // summary says "not a number" instead of printing one.
        if (!diverged_) report(ThermalPlant::kOverheat, "the block's temperature is no longer a finite number "
                                                      "(parameters outside any physical range?)");
        diverged_ = true;
        return;
    }
    if (!overheated_ && block > max_degC_) {
        overheated_ = true;
        char detail[120];
        std::snprintf(detail, sizeof detail, "block at %.1f degC, above the plant's maximum of %.1f degC", block,
                      max_degC_);
        report(ThermalPlant::kOverheat, detail);
    } else if (overheated_ && block < max_degC_ - 5.0) {
        overheated_ = false;  // re-armed after cooling 5 K below the limit
    }
}

double ThermalPlant::block_degC() {
    advance();
    return network_.temperature(block_);
}

double ThermalPlant::sensor_degC() {
    advance();
    if (sensor_ == block_ && detached_) return network_.ambient();
    return network_.temperature(sensor_);
}

double ThermalPlant::surface_degC() {
    advance();
    return network_.temperature(surface_ >= 0 ? surface_ : block_);
}

void ThermalPlant::set_ambient_degC(double degC) {
    advance();
    network_.set_ambient(degC);
}

int ThermalPlant::add_heat_source(const std::string& node, double max_power_W) {
    int n = -1;
    if (node == "block") n = block_;
    if (node == "surface") n = surface_;
    if (n < 0) throw BadInput("plant '" + name() + "' has no node '" + node + "' to heat (block" +
                              (surface_ >= 0 ? ", surface" : "") + ")");
    // Plausibility of the pair: a 40 W cartridge heats the E3D preset's 16.7
    // J/K block at 2.4 K/s, a 120 W bed its 158 J/K at 0.8 K/s; a heater that
    // would heat its node faster than kMaxHeatingRate names parameters no
    // bench holds (and drives the model's temperatures past any meaning).
    const double rate_K_per_s = max_power_W / network_.heat_capacity(n);
    if (!(rate_K_per_s <= kMaxHeatingRate_K_per_s)) {
        char text[200];
        std::snprintf(text, sizeof text, "%.3g W into the %s node of plant '%s' (%.3g J/K) heats it at %.3g K/s, more than %.0f K/s: "
                      "not a physical combination (check supply, resistance, heat_capacity)",
                      max_power_W, node.c_str(), name().c_str(), network_.heat_capacity(n), rate_K_per_s, kMaxHeatingRate_K_per_s);
        throw BadInput(text);
    }
    sources_.emplace_back(n, 0.0);
    return static_cast<int>(sources_.size()) - 1;
}

double ThermalPlant::heater_power_W() const {
    double p = 0;
    for (const auto& s : sources_) p += s.second;
    return p;
}

void ThermalPlant::sensor_read(Cycle cycle) {
    last_sensor_read_ = cycle;
    unmonitored_reported_ = false;  // a new spell, if it comes
}

void ThermalPlant::on_input(std::size_t pin, bool level) {
    // Checked at the samples: a line that only passes high for a moment (pull-ups
    // on before DDR after a reset) is not the firmware saying "ready".
    if (pin == ready_pin_ && !level) ready_reported_ = false;  // a new spell, if it comes
}

void ThermalPlant::check_ready() {
    if (!connected(ready_pin_) || !input_level(ready_pin_) || ready_reported_) return;
    const double sensor = sensor_degC();
    if (sensor >= ready_min_degC_) return;
    ready_reported_ = true;
    char detail[160];
    std::snprintf(detail, sizeof detail, "the firmware says the temperature is reached (ready high) with the sensor at %.1f degC, "
                  "below %.1f degC", sensor, ready_min_degC_);
    report(ThermalPlant::kReadyWhileCold, detail);
}

void ThermalPlant::check_monitoring(Cycle now) {
    const bool heating = heated_since_sample_ || heater_power_W() > 0;
    heated_since_sample_ = false;
    if (sensors_ == 0 || !heating || unmonitored_reported_ || now - last_sensor_read_ < unmonitored_cycles_) return;
    unmonitored_reported_ = true;
    char detail[200];
    std::snprintf(detail, sizeof detail,
                  "heating with no read of its thermistor for %.1f s (the firmware neither controls the temperature "
                  "nor would see a runaway); block at %.1f degC",
                  static_cast<double>(now - last_sensor_read_) / clock().frequency_hz(), network_.temperature(block_));
    report(ThermalPlant::kHeatingUnmonitored, detail);
}

void ThermalPlant::set_heat_source_power(int source, double watts) {
    if (watts > 0) {
        heated_since_sample_ = true;
        heated_ = true;
        last_heat_cycle_ = clock().cycle();
    }
    auto& s = sources_.at(static_cast<std::size_t>(source));
    if (s.second == watts) return;
    advance();
    s.second = watts;
    double node_power = 0;
    for (const auto& o : sources_) {
        if (o.first == s.first) node_power += o.second;
    }
    network_.set_power(s.first, node_power);
}

void ThermalPlant::set_fan_speed(double fraction) {
    fraction = std::clamp(fraction, 0.0, 1.0);
    if (fraction == fan_speed_) return;
    advance();
    fan_speed_ = fraction;
    apply_conductance();
}

void ThermalPlant::set_filament_feed_mm_per_s(double rate) {
    rate = std::max(rate, 0.0);
    if (rate == feed_mm_per_s_) return;
    advance();
    feed_mm_per_s_ = rate;
    apply_conductance();
}

void ThermalPlant::apply_conductance() {
    // Marlin MPC: ambient transfer linear in fan speed between the fan-off and
    // full-speed coefficients; the filament carries heat away as
    // feed (mm/s) x heat capacity per mm (J/(K mm)) x (T_block - T_ambient).
    const double g = g_ambient_ + fan_speed_ * (g_ambient_fan_ - g_ambient_) + feed_mm_per_s_ * filament_J_per_K_mm_;
    network_.set_ambient_conductance(block_, g);
}

void ThermalPlant::set_sensor_detached(bool detached) {
    if (detached == detached_) return;
    advance();
    detached_ = detached;
    if (sensor_ != block_) network_.set_follower_source(sensor_, detached ? ThermalNetwork::kAmbient : block_);
}

// Reads no temperature: advancing the model at other times than a run
// does would change its rounding, and a fuzz input's run would differ from
// its replay.
void ThermalPlant::mark_pace() { pace_cycle_ = clock().cycle(); }

bool ThermalPlant::may_find_more_at_pace(double seconds) {
    (void)seconds;
    return heater_power_W() > 0.0 || (heated_ && last_heat_cycle_ >= pace_cycle_);
}

double ThermalPlant::energy_in_J() {
    advance();
    return network_.energy_in_J();
}

double ThermalPlant::energy_stored_J() {
    advance();
    return network_.energy_stored_J();
}

double ThermalPlant::energy_lost_J() {
    advance();
    return network_.energy_lost_J();
}

void ThermalPlant::reset_energy() {
    advance();
    network_.reset_energy();
}

void ThermalPlant::on_sample(Cycle scheduled) {
    advance();
    if (filament_driver_ != nullptr) {
        // Fresh filament only: a retraction pulls molten filament back, and
        // pushing it in again does not take it from ambient a second time.
        const double steps = static_cast<double>(feed_256_) * filament_driver_->configured_microsteps() / 256.0;
        feed_256_ = 0;
        filament_position_mm_ += steps / filament_steps_per_mm_;
        double fresh = 0;
        if (filament_position_mm_ > filament_high_water_mm_) {
            fresh = filament_position_mm_ - filament_high_water_mm_;
            filament_high_water_mm_ = filament_position_mm_;
        }
        set_filament_feed_mm_per_s(fresh / (static_cast<double>(sample_cycles_) / clock().frequency_hz()));
    }
    publish(sig_block_, network_.temperature(block_));
    publish(sig_sensor_, sensor_ == block_ && detached_ ? network_.ambient() : network_.temperature(sensor_));
    if (surface_ >= 0) publish(sig_surface_, network_.temperature(surface_));
    publish(sig_fan_, fan_speed_);
    check_monitoring(scheduled);
    check_ready();
    clock().scheduler().at(scheduled + sample_cycles_, [this](Cycle c) { on_sample(c); });
}

}  // namespace avrbench
