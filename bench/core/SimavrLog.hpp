// simavr has one process-wide logger. The bench installs its own before simavr
// first speaks, so nothing simavr says reaches stdout/stderr directly: errors
// about a core go to its Mcu (where some become findings), the rest is dropped
// unless AVRBENCH_SIMAVR_LOG is set in the environment (debugging aid).
#pragma once

struct avr_t;

namespace avrbench {

// Receives simavr's LOG_ERROR-or-worse messages about one core.
class SimavrLogSink {
public:
    virtual void on_simavr_error(const char* message) = 0;

protected:
    ~SimavrLogSink() = default;
};

// Idempotent; call before any simavr function that may log.
void install_simavr_log_router();

// Routes `avr`'s messages to `sink` (nullptr detaches). Needs the core's AvrContext (core/AvrContext.hpp).
void route_simavr_log(avr_t* avr, SimavrLogSink* sink);

}  // namespace avrbench
