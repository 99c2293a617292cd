#include "parts/QuadratureEncoder.hpp"

#include <algorithm>
#include <cstdio>

#include "core/Errors.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

const FindingKind QuadratureEncoder::kEdgesTooFast = FindingKind::declare(
    "encoder-edges-too-fast", "quadrature edges closer together than the MCU's decoder takes (missed counts)",
    Severity::Warning);

REGISTER_PART(QuadratureEncoder, "quadrature_encoder");

std::vector<ParamSpec> QuadratureEncoder::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "lines_per_rev", .type = PT::Integer, .default_value = "100",
         .source = "Omron E6B2-C datasheet: 10 to 2000 P/R; 100 P/R is its common small model",
         .help = "pulses per revolution on each channel (4 counts each)", .min = 1, .max = 100000},
        {.name = "full_steps_per_rev", .type = PT::Integer, .default_value = "200",
         .source = "a 1.8 deg hybrid stepper (NEMA 17, e.g. 17HS4401) the encoder sits on",
         .help = "full steps of the shaft per revolution", .min = 1, .max = 100000},
        {.name = "output", .type = PT::Choice, .default_value = "push_pull", .choices = {"push_pull", "open_collector"},
         .source = "E6B2-CWZ5B (voltage output) vs E6B2-CWZ6C (NPN open collector): needs a pull-up",
         .help = "how A and B drive their nets"},
        {.name = "min_edge_spacing", .type = PT::Quantity, .dimension = D::Time, .default_value = "10us",
         .source = "assumed: a pin-change ISR decoding one quadrature step on a 16 MHz AVR takes 100-160 cycles",
         .help = "edges closer than this are counts the firmware's decoder misses (a finding)"},
    };
}

QuadratureEncoder::QuadratureEncoder(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock),
      lines_per_rev_(params.integer("lines_per_rev")),
      full_steps_per_rev_(params.integer("full_steps_per_rev")),
      open_collector_(params.text("output") == "open_collector"),
      min_spacing_cycles_(clock.cycles_from_seconds(params.quantity("min_edge_spacing"))) {
    pin_a_ = add_pin("a", TerminalRole::Output);
    pin_b_ = add_pin("b", TerminalRole::Output);
    sig_count_ = add_signal({"count", true, "", "", ""}, 0);
    require_port<ShaftMotion>("shaft", true, "a step_dir_driver's steps or a stepper motor's shaft",
                              [this](ShaftMotion& shaft) { connect_shaft(shaft); });
}

void QuadratureEncoder::connect_shaft(ShaftMotion& shaft) {
    shaft_ = &shaft;
    start_256_ = shaft.position_256();
    shaft.on_step([this](int) { follow_shaft(); });
}

void QuadratureEncoder::start() {
    // State 00 at the start position (the index of counting).
    drive(pin_a_, false);
    drive(pin_b_, false);
}

void QuadratureEncoder::drive(std::size_t pin, bool level) {
    if (open_collector_ && level) {
        release_output(pin);
    } else {
        drive_output(pin, level);
    }
}

void QuadratureEncoder::follow_shaft() {
    // counts = floor(turned_256 * 4 * lines / (256 * steps_per_rev)), exact in integers.
    const std::int64_t numerator = (shaft_->position_256() - start_256_) * 4 * lines_per_rev_;
    const std::int64_t denominator = 256 * full_steps_per_rev_;
    std::int64_t target = numerator / denominator;
    if (numerator % denominator != 0 && numerator < 0) --target;
    while (count_ != target) step_count(target > count_ ? 1 : -1);
}

void QuadratureEncoder::step_count(int direction) {
    count_ += direction;
    // Gray code: one channel changes per count. State q = count mod 4:
    // 0 -> 00, 1 -> A, 2 -> AB, 3 -> B.
    const auto q = static_cast<int>(((count_ % 4) + 4) % 4);
    const bool a = q == 1 || q == 2;
    const bool b = q >= 2;
    const Cycle now = clock().cycle();
    if (have_edge_) {
        const Cycle gap = now - last_edge_;
        closest_cycles_ = edges_ == 1 ? gap : std::min(closest_cycles_, gap);
        if (gap < min_spacing_cycles_) {
            ++too_close_;
            if (too_close_ == 1) {
                char detail[200];
                std::snprintf(detail, sizeof detail,
                              "A/B edges %.3f us apart, the decoder needs %.3f us (count %lld; the summary counts "
                              "the later ones)",
                              static_cast<double>(gap) * 1e6 / clock().frequency_hz(),
                              static_cast<double>(min_spacing_cycles_) * 1e6 / clock().frequency_hz(),
                              static_cast<long long>(count_));
                report(kEdgesTooFast, detail);
            }
        }
    }
    have_edge_ = true;
    last_edge_ = now;
    ++edges_;
    drive(pin_a_, a);
    drive(pin_b_, b);
    publish(sig_count_, static_cast<double>(count_));
}

std::string QuadratureEncoder::summary() {
    char line[200];
    const double degrees = static_cast<double>(count_) * 360.0 / static_cast<double>(4 * lines_per_rev_);
    std::snprintf(line, sizeof line, "%s: %lld counts (%+.3f deg), %llu edges", name().c_str(),
                  static_cast<long long>(count_), degrees, static_cast<unsigned long long>(edges_));
    std::string out = line;
    if (edges_ >= 2) {
        std::snprintf(line, sizeof line, ", the closest %.3f us apart",
                      static_cast<double>(closest_cycles_) * 1e6 / clock().frequency_hz());
        out += line;
    }
    if (too_close_ > 0) out += ", " + std::to_string(too_close_) + " edges too close for the decoder";
    return out;
}

}  // namespace avrbench
