/*
 * Assembles received bytes into command lines, as a G-code reader needs
 * them: a line ends at '\n' or '\r' (an empty line is skipped); ';' starts
 * a comment to the end of the line and '(' one to the next ')' (RepRap
 * G-code, NIST RS274NGC §3.3.4); letters are upper-cased. A line longer
 * than FW_LINE_MAX is cut there and marked `overflow`, so the firmware can
 * answer it with an error instead of running half a command.
 */
#ifndef FW_LINE_H
#define FW_LINE_H

#include <stdint.h>

#ifndef FW_LINE_MAX
#define FW_LINE_MAX 31
#endif

typedef struct {
    char text[FW_LINE_MAX + 1]; /* NUL-terminated once a line is complete */
    uint8_t length;
    uint8_t overflow;
    uint8_t in_comment; /* 0, ';' or '(' */
    uint8_t complete;   /* text holds a finished line; the next byte starts anew */
} fw_line_t;

/* Feeds one byte; returns 1 when `line->text` holds a complete line (then
 * the next byte starts a new one). */
uint8_t fw_line_feed(fw_line_t *line, char c);

#endif
