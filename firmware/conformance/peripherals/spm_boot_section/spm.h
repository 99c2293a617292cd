/* Shared by the boot loader and the application of spm_boot_section. */
#pragma once

#include <avr/boot.h>
#include <avr/pgmspace.h>
#include <stdint.h>

/* Two pages outside the application's code, page-aligned for the 328P's
 * 128-byte and the 2560's 256-byte pages (SPM_PAGESIZE). */
#define SPM_TARGET_BOOT 0x4000u /* the boot loader programs this one */
#define SPM_TARGET_APP 0x4100u  /* the application tries to program this one */
/* Two pages in the boot section, above the boot loader's code (which ends
 * before FLASHEND + 1 - 2 * 256): the boot loader programs the first before
 * and the second after it programs BLB11 (boot_lock_bits_set). */
#define SPM_TARGET_BOOT_SELF ((uint32_t)FLASHEND + 1u - SPM_PAGESIZE)
#define SPM_TARGET_BOOT_LOCKED ((uint32_t)FLASHEND + 1u - 2u * SPM_PAGESIZE)

static inline uint8_t spm_read(uint32_t address)
{
#if FLASHEND > 0xFFFF
    return pgm_read_byte_far(address);
#else
    return pgm_read_byte((uint16_t)address);
#endif
}

/* Never 0xFF, so an erased page matches it nowhere. */
static inline uint8_t spm_pattern(uint16_t i) { return (uint8_t)((i * 7u + 3u) & 0x7Fu); }

/* Erase, fill and write one page with `value(i)` (or `fill` when value is 0),
 * as avr-libc's <avr/boot.h> documents (boot_page_erase, boot_page_fill,
 * boot_page_write, boot_rww_enable). */
static inline void spm_program_page(uint32_t page, uint8_t use_pattern, uint8_t fill)
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

/* How many bytes of the page at `page` hold spm_pattern(). */
static inline uint16_t spm_pattern_bytes(uint32_t page)
{
    uint16_t matches = 0;
    for (uint16_t i = 0; i < SPM_PAGESIZE; ++i) {
        if (spm_read(page + i) == spm_pattern(i)) ++matches;
    }
    return matches;
}
