/* What main.c shares with the thesis-literal parser (thesis_parser.c). */
#ifndef PRINTER3D_INTERP_INTERP_H
#define PRINTER3D_INTERP_INTERP_H

#include <stdint.h>

void reply(const char *s);
/* A ramped line of a BLU on axis_a and b on axis_b (AXES: none). */
void queue_line(uint8_t axis_a, int32_t a, uint8_t axis_b, int32_t b, uint32_t dtc_half_us, uint8_t deposit);
/* An arc about (start + (ci, cj)) to (x, y), absolute BLU; NULL or why not. */
const char *queue_arc(int32_t ci, int32_t cj, int32_t x, int32_t y, uint8_t cw, uint32_t dtc_half_us, uint8_t deposit);
void set_extruder(uint8_t on);
void home_all(void);
extern volatile int32_t plan_position[];
void thesis_feed(char c);

#endif
