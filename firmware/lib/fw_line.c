#include "fw_line.h"

uint8_t fw_line_feed(fw_line_t *line, char c)
{
    if (line->complete) {
        line->complete = 0;
        line->length = 0;
        line->overflow = 0;
    }
    if (c == '\n' || c == '\r') {
        line->in_comment = 0;
        if (line->length == 0 && !line->overflow) return 0; /* an empty line */
        line->text[line->length] = '\0';
        line->complete = 1;
        return 1;
    }
    if (line->in_comment == ';') return 0;
    if (line->in_comment == '(') {
        if (c == ')') line->in_comment = 0;
        return 0;
    }
    if (c == ';' || c == '(') {
        line->in_comment = (uint8_t)c;
        return 0;
    }
    if (c >= 'a' && c <= 'z') c = (char)(c - 'a' + 'A');
    if (line->length >= FW_LINE_MAX) {
        line->overflow = 1;
        return 0;
    }
    line->text[line->length++] = c;
    return 0;
}
