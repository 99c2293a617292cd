/*
 * The link to seed 001's heater MCU (firmware/printer3d_heater): TWI master
 * at 100 kHz (TWBR = 72, 2560 §24.5.2: 16 MHz / (16 + 2 * 72)); slave 0x30;
 * a 2-byte write sets the setpoint in degC, a 5-byte read returns the
 * temperature in 0.1 degC, the setpoint and TEMP_OK.
 */
#ifndef PRINTER3D_INTERP_HEATER_LINK_H
#define PRINTER3D_INTERP_HEATER_LINK_H

#include <stdint.h>

typedef struct {
    int16_t temp_x10;
    uint16_t setpoint_c;
    uint8_t temp_ok;
} heater_status_t;

void heater_link_init(void);
/* 1 when the heater MCU acknowledged. */
uint8_t heater_set(uint16_t setpoint_c);
uint8_t heater_read(heater_status_t *out);

#endif
