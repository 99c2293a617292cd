#include "periph/Fix.hpp"

#include <cstring>

extern "C" {
#include <sim_io.h>
}

namespace avrbench {

IoWriteHook::IoWriteHook(avr_t* avr, avr_io_addr_t data_address, Handler handler, void* context)
    : avr_(avr), address_(data_address), handler_(handler), context_(context) {
    auto& slot = avr->io[AVR_DATA_TO_IO(data_address)].w;
    original_ = slot.c;
    original_param_ = slot.param;
    slot.c = &IoWriteHook::trampoline;
    slot.param = this;
}

IoWriteHook::~IoWriteHook() {
    auto& slot = avr_->io[AVR_DATA_TO_IO(address_)].w;
    if (slot.param == this) {
        slot.c = original_;
        slot.param = original_param_;
    }
}


void IoWriteHook::trampoline(avr_t* avr, avr_io_addr_t addr, std::uint8_t value, void* param) {
    auto* self = static_cast<IoWriteHook*>(param);
    self->handler_(*self, avr, addr, value);
}

IoReadHook::IoReadHook(avr_t* avr, avr_io_addr_t data_address, Handler handler, void* context)
    : avr_(avr), address_(data_address), handler_(handler), context_(context) {
    auto& slot = avr->io[AVR_DATA_TO_IO(data_address)].r;
    original_ = slot.c;
    original_param_ = slot.param;
    slot.c = &IoReadHook::trampoline;
    slot.param = this;
}

IoReadHook::~IoReadHook() {
    auto& slot = avr_->io[AVR_DATA_TO_IO(address_)].r;
    if (slot.param == this) {
        slot.c = original_;
        slot.param = original_param_;
    }
}


std::uint8_t IoReadHook::trampoline(avr_t* avr, avr_io_addr_t addr, void* param) {
    auto* self = static_cast<IoReadHook*>(param);
    return self->handler_(*self, avr, addr);
}

avr_io_t* find_io_module(avr_t* avr, const char* kind, char name) {
    for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind == nullptr || std::strcmp(io->kind, kind) != 0) continue;
        if (name == 0) return io;
        // Every simavr module struct starts with avr_io_t followed by `char name`
        // for the named kinds (uart, timer, port, spi, twi).
        const char module_name = *reinterpret_cast<const char*>(reinterpret_cast<const std::uint8_t*>(io) + sizeof(avr_io_t));
        if (module_name == name) return io;
    }
    return nullptr;
}

}  // namespace avrbench
