#include "parts/Relay.hpp"

#include "parts/PartRegistry.hpp"

#include <algorithm>

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(Relay, "relay");

std::vector<ParamSpec> Relay::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "operate_time", .type = PT::Quantity, .dimension = D::Time, .default_value = "10ms",
         .source = "Omron G5LE datasheet: operate time 10 ms max (a 5 V PCB relay like seed 004's RL1)",
         .help = "coil energized to contact closed"},
        {.name = "release_time", .type = PT::Quantity, .dimension = D::Time, .default_value = "5ms",
         .source = "Omron G5LE datasheet: release time 5 ms max", .help = "coil off to contact open"},
    };
}

Relay::Relay(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    operate_cycles_ = clock.cycles_from_seconds(params.quantity("operate_time"));
    release_cycles_ = clock.cycles_from_seconds(params.quantity("release_time"));
    coil_pin_ = add_pin("coil", TerminalRole::Input);
    contact_pin_ = add_pin("contact", TerminalRole::Output);
    sig_closed_ = add_signal("closed", false, 0);
}

void Relay::start() { release_output(contact_pin_); }

void Relay::on_input(std::size_t pin, bool level) {
    if (pin != coil_pin_) return;
    // A later coil change cancels a transition still under way.
    const std::uint64_t generation = ++generation_;
    const Cycle delay = level ? operate_cycles_ : release_cycles_;
    clock().scheduler().at(clock().cycle() + delay, [this, generation, level](Cycle) {
        if (generation == generation_) settle(level);
    });
}

void Relay::settle(bool energized) {
    if (energized == closed_) return;
    closed_ = energized;
    if (closed_) {
        ++operations_;
        drive_output(contact_pin_, true);
    } else {
        release_output(contact_pin_);
    }
    publish(sig_closed_, closed_ ? 1 : 0);
}

}  // namespace avrbench
