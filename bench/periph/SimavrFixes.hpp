// Corrections applied to every simavr core the bench creates, where simavr 1.6
// departs from the datasheet or from deterministic virtual time. Each lives in
// core/fixes/ and is listed in docs/FIDELITY.md with the test that pins it.
#pragma once

#include <memory>
#include <vector>

struct avr_t;

namespace avrbench {

class Fix;

// Installs every fix on a freshly initialised core (after avr_init, before
// the firmware runs). Owns the fixes' state: it must live as long as the core.
class SimavrFixes {
public:
    explicit SimavrFixes(avr_t* avr);
    ~SimavrFixes();
    SimavrFixes(const SimavrFixes&) = delete;
    SimavrFixes& operator=(const SimavrFixes&) = delete;

private:
    std::vector<std::unique_ptr<Fix>> fixes_;
};

}  // namespace avrbench
