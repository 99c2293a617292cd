#include "parts/StepDirDriver.hpp"

#include "parts/PartRegistry.hpp"

#include <cmath>
#include <cstdio>

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(StepDirDriver, "step_dir_driver");

const FindingKind StepDirDriver::kStepHighTooShort = FindingKind::declare("step-high-too-short", "STEP active shorter than the driver's minimum", Severity::Warning);
const FindingKind StepDirDriver::kStepLowTooShort = FindingKind::declare("step-low-too-short", "STEP inactive shorter than the driver's minimum", Severity::Warning);
const FindingKind StepDirDriver::kDirSetupViolation = FindingKind::declare("dir-setup-violation", "DIR changed too shortly before an active STEP edge", Severity::Warning);
const FindingKind StepDirDriver::kDirHoldViolation = FindingKind::declare("dir-hold-violation", "DIR changed too shortly after an active STEP edge", Severity::Warning);
const FindingKind StepDirDriver::kStepRateTooHigh = FindingKind::declare("step-rate-too-high", "STEP period shorter than the driver's maximum rate allows", Severity::Warning);
namespace {

// Microstep resolution from the MSx pin levels, bit i = pin i.
//  A4988 (Allegro A4988 datasheet, Table 1 "Microstepping Resolution Truth
//  Table"): MS1 MS2 MS3 = LLL full, HLL 1/2, LHL 1/4, HHL 1/8, HHH 1/16.
//  DRV8825 (TI SLVSA73, Table 1 "Stepping Format"): M0 M1 M2 = 000 full,
//  100 1/2, 010 1/4, 110 1/8, 001 1/16, 101/011/111 1/32.
//  TMC2208 (Trinamic TMC2208 datasheet, "MS1 MS2 microstep setting" in
//  standalone mode): 00 1/8, 10 1/2, 01 1/4, 11 1/16 (interpolated to 1/256
//  internally; the step input counts at this resolution).
unsigned resolution(const std::string& preset, unsigned bits) {
    if (preset == "a4988") {
        switch (bits) {
            case 0b000: return 1;
            case 0b001: return 2;
            case 0b010: return 4;
            case 0b011: return 8;
            case 0b111: return 16;
            default: return 16;  // combinations the datasheet leaves undefined
        }
    }
    if (preset == "drv8825") {
        switch (bits) {
            case 0b000: return 1;
            case 0b001: return 2;
            case 0b010: return 4;
            case 0b011: return 8;
            case 0b100: return 16;
            default: return 32;
        }
    }
    if (preset == "tmc2208") {
        static constexpr unsigned kTable[4] = {8, 2, 4, 16};
        return kTable[bits & 3];
    }
    return 1;
}

std::vector<std::string> microstep_pin_names(const std::string& preset) {
    if (preset == "a4988") return {"ms1", "ms2", "ms3"};
    if (preset == "drv8825") return {"m0", "m1", "m2"};
    if (preset == "tmc2208") return {"ms1", "ms2"};
    return {};
}

std::string format_us(double seconds) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g us", seconds * 1e6);
    return buf;
}

}  // namespace

std::vector<ParamSpec> StepDirDriver::param_specs() {
    using PT = ParamType;
    return {
        {.name = "preset", .type = PT::Choice, .default_value = "generic",
         .choices = {"a4988", "drv8825", "tmc2208", "generic"}, .help = "datasheet timing preset"},
        {.name = "step_edge", .type = PT::Choice, .default_value = "rising", .choices = {"rising", "falling"},
         .help = "active STEP edge"},
        // Timing values 0..1 h: longer is a typo, and cycle counts must fit.
        {.name = "step_high_min", .type = PT::Quantity, .dimension = Dimension::Time, .default_value = "1us",
         .source = "assumed (generic)", .help = "minimum STEP high time", .min = 0, .max = 3600},
        {.name = "step_low_min", .type = PT::Quantity, .dimension = Dimension::Time, .default_value = "1us",
         .source = "assumed (generic)", .help = "minimum STEP low time", .min = 0, .max = 3600},
        {.name = "dir_setup", .type = PT::Quantity, .dimension = Dimension::Time, .default_value = "200ns",
         .source = "assumed (generic)", .help = "DIR setup before the active STEP edge", .min = 0, .max = 3600},
        {.name = "dir_hold", .type = PT::Quantity, .dimension = Dimension::Time, .default_value = "200ns",
         .source = "assumed (generic)", .help = "DIR hold after the active STEP edge", .min = 0, .max = 3600},
        {.name = "max_step_rate", .type = PT::Quantity, .dimension = Dimension::Frequency, .default_value = "500kHz",
         .source = "assumed (generic)", .help = "maximum STEP frequency"},
        {.name = "enable_active", .type = PT::Choice, .default_value = "low", .choices = {"low", "high"},
         .help = "ENABLE level that enables the outputs"},
        {.name = "microsteps", .type = PT::Integer, .default_value = "16", .source = "assumed: all jumpers fitted",
         .help = "resolution when the microstep pins are not wired (jumpers)", .min = 1, .max = 256},
        {.name = "forward_dir", .type = PT::Choice, .default_value = "high", .choices = {"high", "low"},
         .help = "DIR level counted as +"},
        {.name = "current", .type = PT::Quantity, .dimension = Dimension::Current, .default_value = "0.5A",
         .source = "assumed: set with the VREF trimmer",
         .help = "full-scale winding current (a motor part driven by this driver uses it)"},
        {.name = "motor_supply", .type = PT::Quantity, .dimension = Dimension::Voltage, .default_value = "12V",
         .source = "assumed: a 12 V printer/CNC supply",
         .help = "VMOT, the most the chopper can put across a winding"},
    };
}

const std::map<std::string, std::map<std::string, std::string>>& StepDirDriver::presets() {
    static const std::map<std::string, std::map<std::string, std::string>> table = {
        // Allegro A4988 datasheet, Figure 1 "Logic Interface Timing Diagram":
        // STEP high >= 1 us, low >= 1 us; setup and hold of DIR/MSx to the
        // rising STEP edge 200 ns. Max rate from 1/(1 us + 1 us).
        {"a4988", {{"step_edge", "rising"}, {"step_high_min", "1us"}, {"step_low_min", "1us"},
                   {"dir_setup", "200ns"}, {"dir_hold", "200ns"}, {"max_step_rate", "500kHz"},
                   {"enable_active", "low"}}},
        // TI DRV8825 (SLVSA73F) §7.6 "Timing Requirements": f_STEP <= 250 kHz,
        // t_WH(STEP) and t_WL(STEP) >= 1.9 us, t_SU(STEP) and t_H(STEP) >= 650 ns.
        {"drv8825", {{"step_edge", "rising"}, {"step_high_min", "1.9us"}, {"step_low_min", "1.9us"},
                     {"dir_setup", "650ns"}, {"dir_hold", "650ns"}, {"max_step_rate", "250kHz"},
                     {"enable_active", "low"}}},
        // Trinamic TMC2208 datasheet, "STEP and DIR interface timing":
        // t_SH, t_SL >= 100 ns, DIR to STEP setup t_DSU and hold t_DSH >= 20 ns.
        // Max rate from 1/(100 ns + 100 ns). ENN active low.
        {"tmc2208", {{"step_edge", "rising"}, {"step_high_min", "100ns"}, {"step_low_min", "100ns"},
                     {"dir_setup", "20ns"}, {"dir_hold", "20ns"}, {"max_step_rate", "5MHz"},
                     {"enable_active", "low"}}},
        {"generic", {}},
    };
    return table;
}

StepDirDriver::StepDirDriver(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock), preset_(params.text("preset")) {
    step_pin_ = add_pin("step", TerminalRole::Input);
    dir_pin_ = add_pin("dir", TerminalRole::Input);
    enable_pin_ = add_pin("enable", TerminalRole::Input);
    for (const auto& ms : microstep_pin_names(preset_)) ms_pins_.push_back(add_pin(ms, TerminalRole::Input));

    step_active_level_ = params.text("step_edge") == "rising";
    enable_active_level_ = params.text("enable_active") == "high";
    forward_dir_level_ = params.text("forward_dir") == "high";
    step_high_min_cycles_ = cycles(params.quantity("step_high_min"));
    step_low_min_cycles_ = cycles(params.quantity("step_low_min"));
    dir_setup_cycles_ = cycles(params.quantity("dir_setup"));
    dir_hold_cycles_ = cycles(params.quantity("dir_hold"));
    max_step_rate_hz_ = params.quantity("max_step_rate");
    if (max_step_rate_hz_ <= 0) throw part_error(this->name(), "max_step_rate must be positive");
    min_step_period_cycles_ = cycles(1.0 / max_step_rate_hz_);
    const long long microsteps = params.integer("microsteps");
    if (microsteps < 1 || microsteps > 256 || (microsteps & (microsteps - 1)) != 0) {
        throw part_error(this->name(), "microsteps must be a power of two from 1 to 256");
    }
    configured_microsteps_ = static_cast<unsigned>(microsteps);
    current_a_ = params.quantity("current");
    motor_supply_v_ = params.quantity("motor_supply");
    current_microsteps_ = configured_microsteps_;

    sig_step_ = add_signal("step", false);
    sig_dir_ = add_signal("dir", false);
    sig_position_ = add_signal("position_steps", true);
    // Outputs on (1) or off (0), as the ENABLE input and its pull-down decide.
    sig_enabled_ = add_signal("enabled", false, 1);
    provide_port<ShaftMotion>("steps", *this, "the shaft motion an axis or an extruder's filament feed follows");
    provide_port<DriveSource>("windings", *this, "a bipolar motor's two windings, as an ideal chopper");
}

std::string StepDirDriver::tap_problem(const WindingTap& tap) const {
    return tap.phase == 0 || tap.phase == 1 ? std::string{} : "a step/dir driver drives phases A and B only";
}

// A minimum time in cycles, rounded up: a pulse of exactly that length passes.
Cycle StepDirDriver::cycles(double seconds) const {
    const double cycles = std::ceil(seconds * clock().frequency_hz() - 1e-9);
    // A driver's timing minimum is nanoseconds to milliseconds; anything
    // outside 0..1 hour is a typo, and the cast below needs the range.
    if (!(cycles >= 0 && seconds <= 3600)) {
        throw part_error(name(), "a timing value of " + std::to_string(seconds) + " s is outside 0..1 h");
    }
    return static_cast<Cycle>(cycles);
}

void StepDirDriver::start() { publish(sig_enabled_, enabled() ? 1 : 0); }

bool StepDirDriver::enabled() const {
    // The A4988/DRV8825/TMC2208 enable inputs have pull-downs: unwired = enabled.
    if (!connected(enable_pin_)) return true;
    return input_level(enable_pin_) == enable_active_level_;
}

unsigned StepDirDriver::microsteps_from_pins() const {
    bool any_wired = false;
    unsigned bits = 0;
    for (std::size_t i = 0; i < ms_pins_.size(); ++i) {
        if (connected(ms_pins_[i])) {
            any_wired = true;
            if (input_level(ms_pins_[i])) bits |= 1u << i;
        }
    }
    return any_wired ? resolution(preset_, bits) : configured_microsteps_;
}

void StepDirDriver::on_input(std::size_t pin, bool level) {
    if (pin == step_pin_) {
        publish(sig_step_, level ? 1 : 0);
        on_step_edge(level == step_active_level_);
    } else if (pin == dir_pin_) {
        publish(sig_dir_, level ? 1 : 0);
        on_dir_change();
    } else if (pin == enable_pin_) {
        publish(sig_enabled_, enabled() ? 1 : 0);
        notify_drive_change();
    }
}

void StepDirDriver::on_dir_change() {
    const Cycle now = clock().cycle();
    if (enabled() && have_active_edge_ && now - last_active_edge_ < dir_hold_cycles_) {
        report(StepDirDriver::kDirHoldViolation,
               "DIR changed " + std::to_string(now - last_active_edge_) + " cycles after the STEP edge; " + preset_ +
                   " needs " + std::to_string(dir_hold_cycles_) + " cycles of hold");
    }
    have_dir_change_ = true;
    last_dir_change_ = now;
}

void StepDirDriver::on_step_edge(bool active) {
    const Cycle now = clock().cycle();
    if (!active) {
        if (enabled() && have_active_edge_ && now - last_active_edge_ < step_high_min_cycles_) {
            report(StepDirDriver::kStepHighTooShort,
                   "STEP active for " + std::to_string(now - last_active_edge_) + " cycles (" +
                       format_us(static_cast<double>(now - last_active_edge_) / clock().frequency_hz()) + "); " +
                       preset_ + " needs " + std::to_string(step_high_min_cycles_) + " cycles");
        }
        have_inactive_edge_ = true;
        last_inactive_edge_ = now;
        return;
    }
    if (!enabled()) {
        ++steps_ignored_;
        return;
    }
    if (have_inactive_edge_ && now - last_inactive_edge_ < step_low_min_cycles_) {
        report(StepDirDriver::kStepLowTooShort,
               "STEP inactive for " + std::to_string(now - last_inactive_edge_) + " cycles before this edge; " +
                   preset_ + " needs " + std::to_string(step_low_min_cycles_) + " cycles");
    }
    if (have_dir_change_ && now - last_dir_change_ < dir_setup_cycles_) {
        report(StepDirDriver::kDirSetupViolation,
               "DIR changed " + std::to_string(now - last_dir_change_) + " cycles before the STEP edge; " + preset_ +
                   " needs " + std::to_string(dir_setup_cycles_) + " cycles of setup");
    }
    if (have_active_edge_) {
        const Cycle period = now - last_active_edge_;
        if (period > 0) {
            const double rate = clock().frequency_hz() / static_cast<double>(period);
            if (rate > peak_step_rate_hz_) peak_step_rate_hz_ = rate;
        }
        if (period < min_step_period_cycles_) {
            report(StepDirDriver::kStepRateTooHigh,
                   "STEP period " + std::to_string(period) + " cycles; " + preset_ + " allows at most " +
                       std::to_string(static_cast<long long>(max_step_rate_hz_)) + " steps/s");
        }
    }
    have_active_edge_ = true;
    last_active_edge_ = now;

    current_microsteps_ = microsteps_from_pins();
    const int delta = static_cast<int>(256 / current_microsteps_) *
                      (input_level(dir_pin_) == forward_dir_level_ ? 1 : -1);
    position_256_ += delta;
    ++steps_taken_;
    publish(sig_position_, static_cast<double>(position_256_) * configured_microsteps_ / 256.0);
    for (auto& fn : step_listeners_) fn(delta);
    note_activity();
    notify_drive_change();
}

// Forward voltage of the output MOSFETs' body diodes while the outputs are
// disabled (assumed: the drivers' datasheets give ~0.7-1 V).
constexpr double kBodyDiodeV = 0.7;

WindingDrive StepDirDriver::winding(int k) const {
    WindingDrive d;
    if (enabled()) {
        const double e = electrical_angle();
        d.current_mode = true;
        d.target_a = current_a_ * (k == 0 ? std::cos(e) : std::sin(e));
        d.supply_v = motor_supply_v_;
        d.polarity = 1;
    } else {
        d.v_pos = -(motor_supply_v_ + 2 * kBodyDiodeV);
        d.v_neg = motor_supply_v_ + 2 * kBodyDiodeV;
    }
    return d;
}

}  // namespace avrbench

namespace avrbench {

std::string StepDirDriver::motion_summary() const {
    char text[120];
    std::snprintf(text, sizeof text, "%llu steps (%llu ignored while disabled)", static_cast<unsigned long long>(steps_taken_),
                  static_cast<unsigned long long>(steps_ignored_));
    return text;
}

std::string StepDirDriver::rate_summary() const {
    char text[60];
    std::snprintf(text, sizeof text, ", peak %.0f steps/s", peak_step_rate_hz_);
    return text;
}

}  // namespace avrbench
