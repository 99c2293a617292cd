// Every correction the bench applies to a simavr core, one per file in this
// folder; SimavrFixes installs them in this order. docs/FIDELITY.md lists each
// with its datasheet section and test.
#pragma once

#include <memory>

#include "core/fixes/Fix.hpp"

namespace avrbench {

// simavr performs writes above RAMEND past its data buffer; grow it to 64 KiB.
std::unique_ptr<Fix> install_memory_guard(avr_t* avr);
// SLEEP fast-forwards in simulated time only (no usleep).
std::unique_ptr<Fix> install_virtual_sleep(avr_t* avr);
// USART: no usleep on UCSRnA polls, no stdout echo, datasheet frame length.
std::unique_ptr<Fix> install_uart_framing(avr_t* avr);

}  // namespace avrbench
