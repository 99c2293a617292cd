#include "periph/SimavrFixes.hpp"

#include "periph/Fixes.hpp"

namespace avrbench {

SimavrFixes::SimavrFixes(avr_t* avr) {
    for (auto install : {&install_memory_guard, &install_virtual_sleep, &install_uart_framing,
                         // peripherals
                         &install_port_overrides, &install_interrupt_timing, &install_external_interrupts, &install_port_pins,
                         &install_watchdog, &install_adc_conversion, &install_uart_transmitter,
                         &install_uart_ursel, &install_eeprom_timing, &install_spi_timing, &install_spi_slave_select,
                         &install_self_programming,
                         // timers
                         &install_timer_flags, &install_timer_model}) {
        if (auto fix = install(avr)) fixes_.push_back(std::move(fix));
    }
}

SimavrFixes::~SimavrFixes() {
    // Newest first: a fix may use one installed before it (the timers and the
    // USARTs drive pins through install_port_overrides's CompareOutputPins).
    while (!fixes_.empty()) fixes_.pop_back();
}

}  // namespace avrbench
