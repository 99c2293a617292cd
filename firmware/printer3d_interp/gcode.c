#include "gcode.h"

#include <string.h>

uint8_t line_feed(line_reader_t *r, char c)
{
    if (c == '\n' || c == '\r') {
        const uint8_t ready = r->length > 0 || r->overflow || r->star;
        r->text[r->length] = '\0';
        r->in_comment = 0;
        if (!ready) {
            memset(r, 0, sizeof *r);
            return 0;
        }
        return 1;
    }
    if (r->in_comment == ';') return 0;
    if (r->in_comment == '(') {
        if (!r->star) r->xor_before_star ^= (uint8_t)c;
        if (c == ')') r->in_comment = 0;
        return 0;
    }
    if (r->star) {
        if (r->after_star_len < sizeof r->after_star) r->after_star[r->after_star_len++] = (uint8_t)c;
        else r->overflow = 1;
        return 0;
    }
    if (c == '*') {
        r->star = 1;
        return 0;
    }
    if (c == ';') {
        r->in_comment = ';';
        return 0;
    }
    r->xor_before_star ^= (uint8_t)c;
    if (c == '(') {
        r->in_comment = '(';
        return 0;
    }
    if (c == ' ' || c == '\t') return 0;
    if (c >= 'a' && c <= 'z') c = (char)(c - 'a' + 'A');
    if (r->length >= LINE_MAX) {
        r->overflow = 1;
        return 0;
    }
    r->text[r->length++] = c;
    return 0;
}

uint8_t line_checksum_ok(const line_reader_t *r)
{
    if (!r->star) return 1;
    if (r->after_star_len == 0 || r->after_star_len > 3) return 0;
    uint16_t v = 0;
    for (uint8_t i = 0; i < r->after_star_len; ++i) {
        const uint8_t d = r->after_star[i];
        if (d < '0' || d > '9') return 0;
        v = (uint16_t)(v * 10 + (d - '0'));
    }
    return v == r->xor_before_star;
}

/* A decimal number in thousandths, rounded half away from zero; NULL when
 * there is none or it does not fit in 32 bits. */
static const char *parse_milli(const char *p, int32_t *out)
{
    uint8_t negative = 0;
    if (*p == '+' || *p == '-') negative = *p++ == '-';
    uint32_t whole = 0;
    uint8_t digits = 0;
    while (*p >= '0' && *p <= '9') {
        if (whole > 2000000UL) return 0; /* 2e6 * 1000 would not fit */
        whole = whole * 10 + (uint32_t)(*p++ - '0');
        ++digits;
    }
    uint32_t frac = 0; /* in 1e-7 */
    if (*p == '.') {
        ++p;
        uint32_t scale = 1000000UL;
        while (*p >= '0' && *p <= '9') {
            frac += (uint32_t)(*p - '0') * scale;
            scale /= 10;
            ++p;
            ++digits;
        }
    }
    if (digits == 0) return 0;
    const uint32_t milli = whole * 1000UL + (frac + 5000UL) / 10000UL;
    if (milli > 2147483647UL) return 0;
    *out = negative ? -(int32_t)milli : (int32_t)milli;
    return p;
}

uint8_t parse_words(const char *p, words_t *w)
{
    memset(w, 0, sizeof *w);
    w->m = -1;
    while (*p) {
        const char letter = *p++;
        if (letter < 'A' || letter > 'Z') return PARSE_BAD_WORD;
        int32_t v;
        const char *next = parse_milli(p, &v);
        if (!next) return PARSE_BAD_NUMBER;
        p = next;
        w->present |= WORD_BIT(letter);
        w->milli[letter - 'A'] = v;
        if (letter == 'G') {
            if (w->g_count >= 4) return PARSE_TOO_MANY_G;
            w->g[w->g_count++] = v;
        } else if (letter == 'M') {
            if (v < 0 || v % 1000) return PARSE_BAD_NUMBER;
            w->m = v / 1000;
        } else if (letter == 'N') {
            /* Whole numbers; -1 too: hosts reset the count with "N-1 M110". */
            if (v % 1000) return PARSE_BAD_NUMBER;
            w->n = v / 1000;
        }
    }
    return PARSE_OK;
}
