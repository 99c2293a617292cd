/*
 * Code 4.11's G-code parser as the thesis prints it (digest §2, §9.8), for
 * the THESIS_PARSER build of printer3d_interp: a negative fixture. Kept as
 * printed: the line is copied into `char s[50]` with strcpy (a longer line
 * overwrites the stack), every word goes through atof() * BLU_PER_MM into a
 * 16-bit int (more than 32.767 mm wraps), a missing word is 0, F is read
 * per line and `dt_const = 1000000 / gc.f` divides by zero on a line
 * without F, coordinates are relative, and G00 leaves the extruder as it
 * was. Moves run to completion before the next line (the thesis' loop),
 * then "ok" (ours: the thesis has no host protocol); the motion itself is
 * the fixed engine's, so a line moves Z alone first, as the improved build
 * does, and a zero-length XY line does no tick, as the thesis' DDA does.
 */
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "interp.h"
#include "motion.h"

#ifdef THESIS_PARSER

#undef BLU_PER_MM
#define BLU_PER_MM 1000 /* Code 4.11 */

typedef struct {
    char command_letter;
    int command_number;
    int x, y, z, f, i, j, r;
} g_code_t;

static g_code_t gc;
static unsigned int dt_const;
static uint8_t extruder;

static int word(const char *s, char letter)
{
    const char *p = strchr(s, letter);
    return p ? (int)(atof(p + 1) * BLU_PER_MM) : 0;
}

/* Deliberately unsafe: this is the listing. */
static void parse_Gcode_command(const char *command)
{
    char s[50];
    strcpy(s, command);
    gc.command_letter = s[0];
    gc.command_number = atoi(&s[1]);
    gc.x = word(s, 'X');
    gc.y = word(s, 'Y');
    gc.z = word(s, 'Z');
    gc.f = word(s, 'F');
    gc.i = word(s, 'I');
    gc.j = word(s, 'J');
    gc.r = word(s, 'R');
    dt_const = (unsigned int)(1000000L / gc.f); /* dt in microseconds */
    const uint32_t dtc_half_us = 2UL * dt_const;
    if (gc.command_letter == 'G') {
        switch (gc.command_number) {
            case 0:
            case 1:
                if (gc.command_number == 1) extruder = 1;
                /* `G00/G01 Z<z> F<feed>` (§4.6 syntax): Z moves alone,
                 * between layers (§3: "when Z moves, no other motion is
                 * performed"). */
                if (gc.z != 0) {
                    queue_line(AXIS_Z, gc.z, AXES, 0, dtc_half_us, 0);
                    plan_position[AXIS_Z] += gc.z;
                }
                /* L = 0: the DDA's loop (Code 4.1-4.3, "while
                 * number_of_executions < L") runs no tick at all. */
                if (gc.x != 0 || gc.y != 0) {
                    /* G00 leaves the extruder as G01 or M03 left it: on,
                     * it extrudes along the rapid (digest §9.8). */
                    queue_line(AXIS_X, gc.x, AXIS_Y, gc.y, dtc_half_us, extruder);
                    plan_position[AXIS_X] += gc.x;
                    plan_position[AXIS_Y] += gc.y;
                }
                break;
            case 2:
            case 3:
                extruder = 1;
                queue_arc(gc.i, gc.j, plan_position[AXIS_X] + gc.x, plan_position[AXIS_Y] + gc.y,
                          gc.command_number == 2, dtc_half_us, 1);
                break;
            case 28: home_all(); break;
        }
    } else if (gc.command_letter == 'M') {
        if (gc.command_number == 3) set_extruder(extruder = 1);
        if (gc.command_number == 5) set_extruder(extruder = 0);
    }
    motion_wait_idle();
}

static char buffer[128];
static uint8_t length;

void thesis_feed(char c)
{
    if (c == '\r') return;
    if (c != '\n') {
        if (length < sizeof buffer - 1) buffer[length++] = c;
        return;
    }
    buffer[length] = '\0';
    length = 0;
    if (buffer[0] == '\0') return;
    parse_Gcode_command(buffer);
    reply("ok");
}

#endif
