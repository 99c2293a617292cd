/*
 * spm_boot_section, the boot loader half: linked at the start of the boot
 * section (ATmega328P high fuse 0xDE: BOOTSZ = 11, 256 words at 0x7E00;
 * ATmega2560 0xD8: BOOTSZ = 00, 4096 words at 0x3E000) and loaded by the
 * bench as a board's boot loader (Intel HEX). BOOTRST is programmed in both
 * fuse values, so every reset starts here (datasheet, "Boot Loader Support").
 *
 * Like optiboot it looks at MCUSR: after an external reset (EXTRF) it
 * programs page SPM_TARGET_BOOT (application section) and SPM_TARGET_BOOT_SELF
 * (its own section, allowed unless the lock bits forbid it) with
 * spm_pattern(), programs BLB11 with SPM (boot_lock_bits_set: "SPM is not
 * allowed to write to the Boot Loader section"), tries SPM_TARGET_BOOT_LOCKED,
 * and leaves through a watchdog reset (WDE, 16 ms); after any other reset it
 * hands the reset cause to the application in GPIOR0 and jumps to address 0.
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "spm.h"

AVRBENCH_MCU_SECTION();

void boot_entry(void) __attribute__((naked, used, section(".vectors")));
void boot_entry(void)
{
    asm volatile("clr __zero_reg__");
    SP = RAMEND;
    const uint8_t cause = MCUSR;
    MCUSR = 0;
    if (cause & (1 << EXTRF)) {
        spm_program_page(SPM_TARGET_BOOT, 1, 0);
        spm_program_page(SPM_TARGET_BOOT_SELF, 1, 0);
        boot_lock_bits_set(_BV(BLB11));
        spm_program_page(SPM_TARGET_BOOT_LOCKED, 1, 0);
        WDTCSR = (1 << WDCE) | (1 << WDE);
        WDTCSR = (1 << WDE); /* WDP = 0: 16 ms, System Reset Mode */
        for (;;) {
        }
    }
    GPIOR0 = cause;
    asm volatile("jmp 0");
}
