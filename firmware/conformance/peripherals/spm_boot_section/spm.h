/* Shared by the boot loader and the application of spm_boot_section. */
#pragma once

#include <avr/boot.h>
#include <stdint.h>

/* Two pages outside the application's code, page-aligned for the 328P's
 * 128-byte and the 2560's 256-byte pages (SPM_PAGESIZE). */
#define SPM_TARGET_BOOT 0x4000u /* the boot loader programs this one */
#define SPM_TARGET_APP 0x4100u  /* the application tries to program this one */

/* Never 0xFF, so an erased page matches it nowhere. */
static inline uint8_t spm_pattern(uint16_t i) { return (uint8_t)((i * 7u + 3u) & 0x7Fu); }

/* Erase, fill and write one page with `value(i)` (or `fill` when value is 0),
 * as avr-libc's <avr/boot.h> documents (boot_page_erase, boot_page_fill,
 * boot_page_write, boot_rww_enable). */
static inline void spm_program_page(uint16_t page, uint8_t use_pattern, uint8_t fill)
{
    boot_page_erase(page);
    boot_spm_busy_wait();
    for (uint16_t i = 0; i < SPM_PAGESIZE; i += 2) {
        const uint8_t lo = use_pattern ? spm_pattern(i) : fill;
        const uint8_t hi = use_pattern ? spm_pattern(i + 1) : fill;
        boot_page_fill(page + i, (uint16_t)(lo | (hi << 8)));
    }
    boot_page_write(page);
    boot_spm_busy_wait();
    boot_rww_enable();
}
