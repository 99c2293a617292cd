/*
 * G-code lines as a RepRap host sends them (RepRap wiki "G-code": line
 * numbers N, checksum *XX = XOR of every byte before the '*'; comments after
 * ';' or in parentheses, NIST RS274NGC §3.3.4) and their words.
 */
#ifndef PRINTER3D_INTERP_GCODE_H
#define PRINTER3D_INTERP_GCODE_H

#include <stdint.h>

#define LINE_MAX 95

typedef struct {
    char text[LINE_MAX + 1]; /* upper-cased, comments removed, up to the '*' */
    uint8_t length;
    uint8_t overflow;
    uint8_t in_comment;
    uint8_t xor_before_star; /* XOR of the raw bytes before the first '*' */
    uint8_t star;            /* a '*' was seen */
    uint8_t after_star[4];   /* the checksum digits as sent */
    uint8_t after_star_len;
} line_reader_t;

/* Feeds a received byte; 1 when a complete, non-empty line is ready (the
 * reader starts over on the next call). */
uint8_t line_feed(line_reader_t *r, char c);
/* 1 when the line carries no checksum or a correct one. */
uint8_t line_checksum_ok(const line_reader_t *r);

/* Words of one line. Numbers are kept in thousandths (G1 -> 1000, X12.3456
 * -> 12346, rounded half away from zero); at most 7 decimals are read. */
#define WORD_BIT(letter) (1UL << ((letter) - 'A'))
typedef struct {
    uint32_t present;      /* WORD_BIT per letter seen */
    int32_t milli[26];     /* the last value of each letter */
    int32_t g[4];          /* every G word, in order (thousandths) */
    uint8_t g_count;
    int32_t m;             /* the M word (whole number), -1 if none */
    int32_t n;             /* the N word, if present */
} words_t;

enum parse_error { PARSE_OK, PARSE_BAD_WORD, PARSE_BAD_NUMBER, PARSE_TOO_MANY_G };
/* Splits `text` into words. */
uint8_t parse_words(const char *text, words_t *w);

#endif
