/*
 * spm_boot_section, the application half (see boot.c).
 *
 * "The SPM instruction can access the entire Flash, but it can only be
 * executed from the Boot Loader Flash section" (ATmega328P and ATmega2560
 * datasheets, "Boot Loader Support - Read-While-Write Self-Programming"):
 * the application runs the same erase/fill/write sequence on page
 * SPM_TARGET_APP with zeros, which must leave it erased (0xFF).
 *
 * Results in RAM, read by tests/conformance_periph/test_spm_boot_section.cpp:
 *  - reset_cause: GPIOR0 as the boot loader left it (its MCUSR copy);
 *  - boot_page_pattern_bytes: bytes of SPM_TARGET_BOOT equal to spm_pattern();
 *  - boot_self_pattern_bytes, boot_locked_pattern_bytes: the same for the
 *    two pages in the boot section;
 *  - app_page_erased_bytes: bytes of SPM_TARGET_APP still 0xFF after the
 *    application's SPM sequence;
 *  - done: 1 once the three above are set.
 */
#include <avr/io.h>
#include <avr/pgmspace.h>

#include "avrbench_mcu.h"
#include "spm.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t reset_cause;
volatile uint16_t boot_page_pattern_bytes;
volatile uint16_t boot_self_pattern_bytes;
volatile uint16_t boot_locked_pattern_bytes;
volatile uint16_t app_page_erased_bytes;
volatile uint8_t done;

int main(void)
{
    reset_cause = GPIOR0;
    boot_page_pattern_bytes = spm_pattern_bytes(SPM_TARGET_BOOT);
    boot_self_pattern_bytes = spm_pattern_bytes(SPM_TARGET_BOOT_SELF);
    boot_locked_pattern_bytes = spm_pattern_bytes(SPM_TARGET_BOOT_LOCKED);

    spm_program_page(SPM_TARGET_APP, 0, 0x00);
    uint16_t erased = 0;
    for (uint16_t i = 0; i < SPM_PAGESIZE; ++i) {
        if (spm_read(SPM_TARGET_APP + i) == 0xFF) ++erased;
    }
    app_page_erased_bytes = erased;
    done = 1;
    for (;;) {
    }
}
