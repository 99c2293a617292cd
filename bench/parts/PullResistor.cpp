#include "parts/PullResistor.hpp"

#include "parts/PartRegistry.hpp"

#include <cmath>

#include "core/Errors.hpp"

namespace avrbench {

REGISTER_PART(PullResistor, "pull_resistor");

std::vector<ParamSpec> PullResistor::param_specs() {
    using PT = ParamType;
    return {
        {.name = "to", .type = PT::Choice, .required = true, .choices = {"vcc", "gnd"},
         .help = "the rail the resistor goes to"},
        {.name = "resistance", .type = PT::Quantity, .dimension = Dimension::Resistance, .default_value = "10kohm",
         .source = "assumed: the usual 10 kohm", .help = "0 ohm ties the net to the rail (a strong driver)"},
    };
}

PullResistor::PullResistor(std::string name, Mcu& clock, const ParamValues& params)
    : Part(std::move(name), clock), to_vcc_(params.text("to") == "vcc"), ohms_(params.quantity("resistance")) {
    // 100 Mohm: beyond that a "pull" is leakage, not a resistor anyone fits.
    if (!(ohms_ >= 0 && ohms_ <= 100e6)) {
        throw part_error(this->name(), "resistance must be from 0 to 100 Mohm");
    }
    pin_ = add_pin("pin", TerminalRole::Output);
}

void PullResistor::start() {
    if (ohms_ == 0) {
        drive_output(pin_, to_vcc_);
    } else {
        pull_output(pin_, to_vcc_, ohms_);
    }
}

}  // namespace avrbench
