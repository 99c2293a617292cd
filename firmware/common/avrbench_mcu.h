/*
 * avrbench_mcu.h - make a firmware ELF self-describing for simavr.
 *
 * Write AVRBENCH_MCU_SECTION(); once at file scope in each firmware. It
 * expands to simavr's AVR_MCU(F_CPU, "<mcu>"), which puts the MCU name and the
 * clock into the ELF's .mmcu section, so the bench can load the very file that
 * would be flashed without being told --mcu/--freq.
 *
 * The build (firmware/CMakeLists.txt) defines:
 *   F_CPU               clock in Hz (also used by avr-libc's <util/delay.h>)
 *   AVRBENCH_MCU_NAME   the -mmcu string, e.g. "atmega328p"
 *   AVRBENCH_NO_MMCU    for builds that must NOT carry a .mmcu section
 *                       (they test the bench's --mcu/--freq fallback)
 */
#ifndef AVRBENCH_MCU_H
#define AVRBENCH_MCU_H

#ifndef F_CPU
#error "F_CPU must be defined by the build (avr_firmware F_CPU <hz>)"
#endif

#if defined(AVRBENCH_NO_MMCU)
/* Expands to a harmless declaration so the trailing ';' stays valid C. */
#define AVRBENCH_MCU_SECTION() extern char avrbench_no_mmcu_section_
#else
#ifndef AVRBENCH_MCU_NAME
#error "AVRBENCH_MCU_NAME must be defined by the build (avr_firmware MCU <mmcu>)"
#endif
#include "avr_mcu_section.h"
#define AVRBENCH_MCU_SECTION() AVR_MCU(F_CPU, AVRBENCH_MCU_NAME)
#endif

#endif /* AVRBENCH_MCU_H */
