#include "parts/RcServo.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(RcServo, "rc_servo");

const FindingKind RcServo::kServoPulseOutOfRange = FindingKind::declare("servo-pulse-out-of-range", "an RC servo pulse wider or narrower than its calibrated range", Severity::Warning);
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

}  // namespace

std::vector<ParamSpec> RcServo::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    std::vector<ParamSpec> specs = {
        {.name = "calibration", .type = PT::Text, .default_value = "0:544,180:2400",
         .source = "the Arduino Servo library's default pulse limits (MIN_PULSE_WIDTH 544 us, MAX_PULSE_WIDTH 2400 us for 0..180 deg)",
         .help = "degrees:microseconds pairs, both ascending, e.g. [T4] Table 4.1's 0:641,45:1032,90:1474,135:1902,180:2305"},
        {.name = "slew_deg_per_s", .type = PT::Quantity, .default_value = "600",
         .source = "TowerPro SG90 datasheet: 0.1 s/60 deg at 4.8 V",
         .help = "the horn's top speed ([T4]'s servo: 285)"},
        {.name = "dead_band", .type = PT::Quantity, .dimension = D::Time, .default_value = "10us",
         .source = "TowerPro SG90 datasheet: dead band width 10 us",
         .help = "a pulse this close to the last accepted one is not a new command"},
        {.name = "initial_angle", .type = PT::Quantity, .dimension = D::Angle, .default_value = "90deg",
         .source = "assumed: centred at power-on", .help = "where the horn is before the first pulse"},
        {.name = "min_pulse", .type = PT::Quantity, .dimension = D::Time, .default_value = "400us",
         .source = "assumed: shorter pulses are glitches, not commands",
         .help = "pulses shorter than this are ignored"},
        {.name = "max_pulse", .type = PT::Quantity, .dimension = D::Time, .default_value = "3000us",
         .source = "assumed: longer pulses are not servo frames", .help = "pulses longer than this are ignored"},
    };
    specs[1].min = 1;
    specs[1].max = 100000;
    specs[2].max = 1e-3;
    return specs;
}

RcServo::RcServo(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      slew_deg_per_s_(params.quantity("slew_deg_per_s")),
      dead_band_us_(params.quantity("dead_band") * 1e6),
      min_pulse_us_(params.quantity("min_pulse") * 1e6),
      max_pulse_us_(params.quantity("max_pulse") * 1e6) {
    std::istringstream in(params.text("calibration"));
    std::string item;
    while (std::getline(in, item, ',')) {
        Point p{};
        char extra = 0;
        if (std::sscanf(item.c_str(), " %lf : %lf %c", &p.deg, &p.us, &extra) != 2) {
            throw part_error(this->name(), "calibration: '" + item + "' is not degrees:microseconds");
        }
        if (!table_.empty() && (p.deg <= table_.back().deg || p.us <= table_.back().us)) {
            throw part_error(this->name(), "calibration: '" + item +
                           "' does not ascend in both degrees and microseconds");
        }
        table_.push_back(p);
    }
    if (table_.size() < 2) throw part_error(this->name(), "calibration needs at least two points");
    const double initial = params.quantity("initial_angle") * kRadToDeg;
    from_deg_ = target_deg_ = std::clamp(initial, table_.front().deg, table_.back().deg);
    signal_pin_ = add_pin("signal", TerminalRole::Input);

    sig_angle_ = add_signal({"angle_deg", true, "deg", "servo-angle", ""}, from_deg_);
    sig_target_ = add_signal({"target_deg", true, "deg", "", ""}, target_deg_);
    sig_pulse_ = add_signal({"pulse_us", true, "us", "", ""}, 0);
    provide_port<ServoHorn>("horn", *this, "the output shaft a mechanism's arm is fixed to");
}

double RcServo::angle_for_pulse_us(double width_us) const {
    if (width_us <= table_.front().us) return table_.front().deg;
    if (width_us >= table_.back().us) return table_.back().deg;
    const auto hi = std::upper_bound(table_.begin(), table_.end(), width_us,
                                     [](double w, const Point& p) { return w < p.us; });
    const Point& b = *hi;
    const Point& a = *(hi - 1);
    return a.deg + (b.deg - a.deg) * (width_us - a.us) / (b.us - a.us);
}

double RcServo::angle_at(Cycle cycle) const {
    const double elapsed_s = static_cast<double>(cycle - motion_start_) / clock().frequency_hz();
    const double travel = slew_deg_per_s_ * elapsed_s;
    const double distance = target_deg_ - from_deg_;
    if (travel >= std::abs(distance)) return target_deg_;
    return from_deg_ + std::copysign(travel, distance);
}

double RcServo::angle_deg() const { return angle_at(clock().cycle()); }

void RcServo::on_input(std::size_t pin, bool level) {
    if (pin != signal_pin_ || level == high_) return;
    high_ = level;
    const Cycle now = clock().cycle();
    if (level) {
        rise_cycle_ = now;
        return;
    }
    const double width_us = static_cast<double>(now - rise_cycle_) * 1e6 / clock().frequency_hz();
    if (width_us < min_pulse_us_ || width_us > max_pulse_us_) {
        // The servo ignores it (no valid command), but the firmware sent it:
        // seed 004's digest §8 "no servo pulse is outside 500..2500 us".
        if (!out_of_range_) {
            char detail[160];
            std::snprintf(detail, sizeof detail, "pulse of %.1f us is outside the %.0f..%.0f us the servo accepts; ignored",
                          width_us, min_pulse_us_, max_pulse_us_);
            report(RcServo::kServoPulseOutOfRange, detail);
        }
        out_of_range_ = true;
        return;
    }
    on_pulse(width_us, now);
}

void RcServo::on_pulse(double width_us, Cycle end) {
    ++pulses_;
    last_pulse_us_ = width_us;
    publish(sig_pulse_, width_us);
    const bool outside = width_us < table_.front().us || width_us > table_.back().us;
    if (outside && !out_of_range_) {
        char detail[160];
        std::snprintf(detail, sizeof detail, "pulse of %.1f us is outside the calibrated %.0f..%.0f us; clamped to %.1f deg",
                      width_us, table_.front().us, table_.back().us, angle_for_pulse_us(width_us));
        report(RcServo::kServoPulseOutOfRange, detail);
    }
    out_of_range_ = outside;
    const double now_deg = angle_at(end);
    publish(sig_angle_, now_deg);
    if (accepted_us_ >= 0 && std::abs(width_us - accepted_us_) < dead_band_us_) return;
    accepted_us_ = width_us;
    const double target = angle_for_pulse_us(width_us);
    if (target == target_deg_ && now_deg == target_deg_) return;
    from_deg_ = now_deg;
    target_deg_ = target;
    motion_start_ = end;
    publish(sig_target_, target_deg_);
    // The arrival, so the trace holds the exact end of the move.
    const double seconds = std::abs(target_deg_ - from_deg_) / slew_deg_per_s_;
    const Cycle arrival = end + clock().cycles_from_seconds(seconds);
    const std::uint64_t generation = ++arrival_generation_;
    clock().scheduler().at(arrival, [this, generation](Cycle) {
        if (generation == arrival_generation_) publish(sig_angle_, target_deg_);
    });
}

std::string RcServo::summary() {
    char line[160];
    std::snprintf(line, sizeof line, "servo %-5s %.2f deg (target %.2f), %u pulses, last %.1f us", name().c_str(),
                  angle_deg(), target_deg_, pulses_, last_pulse_us_);
    return line;
}

}  // namespace avrbench
