// SPM executes only from the boot loader section (ATmega328P datasheet,
// "Boot Loader Support - Read-While-Write Self-Programming": "the SPM
// instruction can access the entire Flash, but it can only be executed from
// the Boot Loader Flash section"; the same chapter in the ATmega2560's).
// simavr 1.6's flash module (avr_flash.c) erases and writes pages for an SPM
// anywhere in flash. Here an SPM whose address lies below the boot section
// (BOOTSZ fuse bits, core/BootSection.hpp) does nothing; SPMEN still
// clears by itself four cycles after it was set, as simavr already times.
//
// Not corrected (documented in docs/FIDELITY.md): page erase and write take
// no time (the datasheet's tWD_FLASH, 3.7-4.5 ms, with RWWSB set meanwhile);
// the boot lock bits (BLB0/BLB1) are not enforced; MCUCR.IVSEL does not move
// the interrupt vectors into the boot section.
extern "C" {
#include <avr_flash.h>
}

#include <atomic>

#include "core/BootSection.hpp"
#include "core/fixes/Fixes.hpp"

namespace avrbench {
namespace {

// simavr's avr_flash_ioctl: one static function for every core of the library.
std::atomic<int (*)(avr_io_t*, std::uint32_t, void*)> g_simavr_flash_ioctl{nullptr};

int flash_ioctl_from_boot_section_only(avr_io_t* port, std::uint32_t ctl, void* param) {
    if (ctl == AVR_IOCTL_FLASH_SPM) {
        avr_t* avr = port->avr;
        // During the SPM instruction avr->pc still holds its address (avr_run_one
        // sets the new PC after the instruction).
        const auto boot = boot_section(avr->mmcu, avr->fuse);
        if (boot && avr->pc < boot->start_bytes) return 0;  // handled: no effect
    }
    return g_simavr_flash_ioctl.load()(port, ctl, param);
}

}  // namespace

std::unique_ptr<Fix> install_self_programming(avr_t* avr) {
    avr_io_t* flash = find_io_module(avr, "flash");
    if (flash == nullptr || flash->ioctl == nullptr) return nullptr;
    if (flash->ioctl != &flash_ioctl_from_boot_section_only) {
        g_simavr_flash_ioctl.store(flash->ioctl);
        flash->ioctl = &flash_ioctl_from_boot_section_only;
    }
    return nullptr;  // no state: the module's own function pointer is the hook
}

}  // namespace avrbench
