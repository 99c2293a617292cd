// SPM executes only from the boot loader section (ATmega328P datasheet,
// "Boot Loader Support - Read-While-Write Self-Programming": "the SPM
// instruction can access the entire Flash, but it can only be executed from
// the Boot Loader Flash section"; the same chapter in the ATmega2560's).
// simavr 1.6's flash module (avr_flash.c) erases and writes pages for an SPM
// anywhere in flash. Here an SPM whose address lies below the boot section
// (BOOTSZ fuse bits, periph/memory/BootSection.hpp) does nothing; SPMEN still
// clears by itself four cycles after it was set, as simavr already times.
//
// The boot lock bits restrict what SPM may write (same chapter, "Boot Lock
// Bit0/Bit1 Protection Modes"; lock byte: LB1..2 bits 1..0, BLB01/BLB02 bits
// 2..3 for the application section, BLB11/BLB12 bits 4..5 for the boot
// section; a bit is programmed when 0): with BLBx1 = 0 (modes 2 and 3) "SPM
// is not allowed to write to" that section, so its page erases and page
// writes do nothing. SPM with BLBSET programs lock bits from R0 (simavr
// ignores it). simavr 1.6 enforces none of this.
//
// Not corrected (documented in docs/FIDELITY.md): page erase and write take
// no time (the datasheet's 3.7-4.5 ms, with RWWSB set meanwhile); the LPM
// restrictions of modes 3 and 4 (simavr's LPM reads flash directly, no hook);
// MCUCR.IVSEL does not move the interrupt vectors into the boot section.
extern "C" {
#include <avr_flash.h>
}

#include <atomic>

#include "periph/memory/BootSection.hpp"
#include "periph/Fixes.hpp"

namespace avrbench {
namespace {

// simavr's avr_flash_ioctl: one static function for every core of the library.
std::atomic<int (*)(avr_io_t*, std::uint32_t, void*)> g_simavr_flash_ioctl{nullptr};

int flash_ioctl_from_boot_section_only(avr_io_t* port, std::uint32_t ctl, void* param) {
    if (ctl == AVR_IOCTL_FLASH_SPM) {
        avr_t* avr = port->avr;
        const auto* flash = reinterpret_cast<const avr_flash_t*>(port);  // avr_io_t is its first member
        // During the SPM instruction avr->pc still holds its address (avr_run_one
        // sets the new PC after the instruction).
        const auto boot = boot_section(avr->mmcu, avr->fuse);
        if (boot && avr->pc < boot->start_bytes) return 0;  // handled: no effect
        if (boot && avr_regbit_get(avr, flash->selfprgen)) {
            if (avr_regbit_get(avr, flash->blbset)) {
                // Only programming (1 -> 0) is possible; bits 7..6 do not exist.
                avr->lockbits &= static_cast<std::uint8_t>(avr->data[0] | 0xC0);
                avr_regbit_clear(avr, flash->selfprgen);
                return 0;
            }
            if (avr_regbit_get(avr, flash->pgers) || avr_regbit_get(avr, flash->pgwrt)) {
                std::uint32_t z = avr->data[R_ZL] | (avr->data[R_ZH] << 8);
                if (avr->rampz) z |= static_cast<std::uint32_t>(avr->data[avr->rampz]) << 16;
                const unsigned blbx1 = z >= boot->start_bytes ? 4 : 2;  // BLB11 or BLB01
                if ((avr->lockbits & (1u << blbx1)) == 0) {
                    avr_regbit_clear(avr, flash->selfprgen);
                    return 0;  // the section is locked against SPM writes
                }
            }
        }
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
