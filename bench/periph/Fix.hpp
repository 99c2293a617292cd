// Building blocks for the corrections in SimavrFixes: one file per fix in
// this folder, each an `install_...(avr_t*)` returning the state it needs to
// keep alive (or nullptr), registered in SimavrFixes.cpp.
#pragma once

#include <cstdint>
#include <memory>

#include "core/IoHook.hpp"

extern "C" {
#include <sim_avr.h>
}

namespace avrbench {

// State a fix keeps for the lifetime of its core.
class Fix {
public:
    virtual ~Fix() = default;
};

// The simavr I/O module of a kind ("uart", "timer", "port", "adc",
// "watchdog", ...) and optional name character, or nullptr. The returned
// pointer is the module's avr_io_t, the first member of its specific struct.
avr_io_t* find_io_module(avr_t* avr, const char* kind, char name = 0);

}  // namespace avrbench
