#include "core/SimavrFixes.hpp"

#include "core/fixes/Fixes.hpp"

namespace avrbench {

SimavrFixes::SimavrFixes(avr_t* avr) {
    for (auto install : {&install_memory_guard, &install_virtual_sleep, &install_uart_framing}) {
        if (auto fix = install(avr)) fixes_.push_back(std::move(fix));
    }
}

SimavrFixes::~SimavrFixes() = default;

}  // namespace avrbench
