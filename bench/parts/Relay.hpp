// An electromechanical relay with a normally-open contact: the coil pin
// energizes it, and the contact follows after the operate time (closing) or
// the release time (opening). The closed contact drives `contact` to the
// switched supply (a level 1); open, the contact is released (a load behind it
// sees no drive). Seed 004 switches its electromagnet and its warning LED
// through two such relays.
#pragma once

#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class Relay final : public Part {
public:
    static std::vector<ParamSpec> param_specs();

    Relay(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "relay"; }
    void start() override;

    bool closed() const { return closed_; }
    unsigned operations() const { return operations_; }

private:
    void on_input(std::size_t pin, bool level) override;
    void settle(bool energized);

    std::size_t coil_pin_, contact_pin_;
    Cycle operate_cycles_, release_cycles_;
    bool closed_ = false;
    unsigned operations_ = 0;
    std::uint64_t generation_ = 0;
    std::size_t sig_closed_;
};

}  // namespace avrbench
