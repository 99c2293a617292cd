#include "core/SimavrLog.hpp"

#include "core/AvrContext.hpp"

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <mutex>

extern "C" {
#include <sim_avr.h>
}

namespace avrbench {
namespace {

bool echo_requested() {
    static const bool echo = std::getenv("AVRBENCH_SIMAVR_LOG") != nullptr;
    return echo;
}

void route(avr_t* avr, const int level, const char* format, va_list args) {
    const AvrContext* context = avr != nullptr ? AvrContext::of(avr) : nullptr;
    SimavrLogSink* sink = context != nullptr ? context->log_sink : nullptr;
    const bool to_sink = level <= LOG_ERROR && sink != nullptr;
    if (!to_sink && !echo_requested()) return;
    char message[512];
    std::vsnprintf(message, sizeof message, format, args);
    if (echo_requested()) std::fprintf(stderr, "simavr: %s", message);
    if (to_sink) sink->on_simavr_error(message);
}

}  // namespace

void install_simavr_log_router() {
    static std::once_flag once;
    std::call_once(once, [] { avr_global_logger_set(&route); });
}

void route_simavr_log(avr_t* avr, SimavrLogSink* sink) {
    if (AvrContext* context = AvrContext::of(avr)) context->log_sink = sink;
}

}  // namespace avrbench
