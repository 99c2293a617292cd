/*
 * host_peer - the serial protocol of a printer/CNC firmware family, as its
 * documentation and sources describe it, without the machine behind it:
 * what the bench's UART host must cope with. USART0 at 115200 baud (U2X0,
 * UBRR0 = 16), polled. One build per family (-DFAMILY_GRBL/_MARLIN/_PRUSA/
 * _TEACUP/_SPRINTER/_REPETIER).
 *
 * grbl 1.1 (doc/markdown/interface.md; on a blank EEPROM): before its
 *   welcome it reports the EEPROM error and its settings ("error:7",
 *   "$0=10", ...), then prints "Grbl 1.1h ['$' for help]", then the results
 *   of its two startup lines (">:error:7" twice: the blank startup blocks).
 *   Input received before the welcome is discarded (serial_reset_read_buffer).
 *   Each line is answered "ok"; "G4 P<s>" after the dwell (grbl's P is in
 *   seconds, as in LinuxCNC); "BUSY<s>" works that long before its ok but
 *   answers the realtime status query '?' meanwhile, as grbl does mid-move;
 *   "RESET" makes it
 *   reset (watchdog) and print all of the above again.
 * Marlin 1.x: "start", "echo:" lines, then an SD card probe that takes 2.1 s
 *   before "echo:SD init fail"; each line "ok"; "M109 ..." prints
 *   "echo:busy: processing" every second for 5 s, then "ok"; a line
 *   containing "*99" (a bad checksum) gets "Error:checksum mismatch, Last
 *   Line: 0", "Resend: 1", "ok" the first time and "ok" when sent again.
 *   "G4 P<ms>" is answered "ok" when it is read (Marlin queues it) and then
 *   dwells that long, printing "busy: processing" every 2000 ms
 *   (HOST_KEEPALIVE_FEATURE, DEFAULT_KEEPALIVE_INTERVAL 2 in Marlin's
 *   Configuration_adv.h): the next line waits unanswered in the meantime.
 *   "KILL" prints "Error:Printer halted. kill() called!" and "FATAL" prints
 *   "fatal:Homing failed!" - then either halts for good, answering nothing.
 *   A line it does not know ("M9999", "G5 ...": it knows G0-G4, G28,
 *   G90-G92, M104-M114) gets `echo:Unknown command: "<line>"` before its ok
 *   (Marlin_main.cpp, MSG_UNKNOWN_COMMAND, then ClearToSend()).
 * Prusa-Firmware (MK3S, Marlin_main.cpp): Marlin's, but an unknown G or M
 *   code is "Unknown G code: <line>" (MSG_UNKNOWN_CODE "Unknown %c code:
 *   %s") before the ok.
 * Teacup: "start" and a boot "ok"; each line "ok"; "M116" waits 5 s in
 *   silence, then "ok"; "QUEUED_M116" is Teacup's real M116: "ok" at once
 *   (it is queued), then "Waiting for target temp" at once and every second
 *   after for 4 s (clock.c's once-a-second report) while nothing else is
 *   read; an unknown G or M code gets "E: Bad G-code <n>" /
 *   "E: Bad M-code <n>" before the ok (gcode_process.c); "*99" (a bad
 *   checksum) gets "rs N1 Expected checksum 17" and the ok the first time
 *   (gcode_parse.c: the line is not run).
 * Sprinter: "start"; each line "ok"; an unknown G or M code gets
 *   "Unknown G-COM:<line>" / "Unknown M-COM:<line>" before the ok
 *   (Sprinter.pde with SEND_WRONG_CMD_INFO); "*99" gets "Serial Error: Line
 *   Number is not Last Line Number+1, Last Line:0", "Resend:1" and "ok" the
 *   first time (FlushSerialRequestResend).
 * Repetier 1.0: "start"; each line "ok" as soon as it is queued; an unknown
 *   command is reported when it runs, after that ok, as "Unknown command:
 *   M9999 " (Commands.cpp, GCode::printCommand); "wait" when idle a second
 *   (WAITING_IDENTIFIER).
 */
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <avr/wdt.h>
#include <stdlib.h>
#include <string.h>
#include <util/delay.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

/* The watchdog stays on after a watchdog reset: turn it off first thing. */
__attribute__((naked, used, section(".init3"))) void wdt_off_at_boot(void)
{
    MCUSR = 0;
    wdt_disable();
}

static void put(char c)
{
    loop_until_bit_is_set(UCSR0A, UDRE0);
    UDR0 = (uint8_t)c;
}

static void print_P(const char *text)
{
    char c;
    while ((c = (char)pgm_read_byte(text++)) != '\0') put(c);
}

#define SAY(literal) print_P(PSTR(literal "\r\n"))

static char line[96];

#if defined(FAMILY_GRBL)
/* grbl picks realtime bytes out of the stream at once: '?' is answered with
 * a status report, whatever the main loop is doing. */
static uint8_t realtime(char c)
{
    if (c != '?') return 0;
    print_P(PSTR("<Idle|MPos:0.000,0.000,0.000|FS:0,0>\r\n"));
    return 1;
}

/* `seconds` of work that still answers realtime queries ("BUSY<s>"). */
static void busy(long seconds)
{
    for (long ms = seconds * 1000L; ms > 0; --ms) {
        if (bit_is_set(UCSR0A, RXC0)) realtime((char)UDR0);
        _delay_ms(1);
    }
}
#else
static uint8_t realtime(char c)
{
    (void)c;
    return 0;
}
#endif

/* One line from the host (without its line end), polled. */
static void read_line(void)
{
    uint8_t n = 0;
    for (;;) {
        loop_until_bit_is_set(UCSR0A, RXC0);
        const char c = (char)UDR0;
        if (realtime(c)) continue;
        if (c == '\n' || c == '\r') {
            if (n == 0) continue;
            line[n] = '\0';
            return;
        }
        if (n < sizeof line - 1) line[n++] = c;
    }
}

/* The commands the printer families know here: G0-G4, G28, G90-G92,
 * M104-M114; any other G or M number is unknown. */
__attribute__((unused)) static uint8_t known_command(void)
{
    const char *p = line;
    if (*p == 'N') {
        while (*p != '\0' && *p != ' ') ++p;
        while (*p == ' ') ++p;
    }
    if (*p != 'G' && *p != 'M') return 1; /* not a G or M line: nothing to refuse */
    const int n = atoi(p + 1);
    if (*p == 'G') return n <= 4 || n == 28 || (n >= 90 && n <= 92);
    return n >= 104 && n <= 114;
}

/* "Unknown command: "<line>"" and friends: the prefix, then the line. */
__attribute__((unused)) static void say_unknown(const char *prefix, const char *suffix)
{
    print_P(prefix);
    for (const char *p = line; *p != '\0'; ++p) put(*p);
    print_P(suffix);
}

__attribute__((unused)) static void discard_input(void)
{
    while (bit_is_set(UCSR0A, RXC0)) (void)UDR0;
}

int main(void)
{
    UCSR0A = _BV(U2X0);
    UBRR0 = 16;
    UCSR0B = _BV(RXEN0) | _BV(TXEN0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);

#if defined(FAMILY_GRBL)
    SAY("error:7");
    SAY("$0=10");
    SAY("$1=25");
    SAY("$100=250.000");
    discard_input();
    SAY("Grbl 1.1h ['$' for help]");
    SAY(">:error:7");
    SAY(">:error:7");
    for (;;) {
        read_line();
        if (strcmp_P(line, PSTR("RESET")) == 0) {
            wdt_enable(WDTO_15MS);
            for (;;) {
            }
        }
        if (strncmp_P(line, PSTR("G4 P"), 4) == 0) {
            for (long ms = atol(line + 4) * 1000L; ms > 0; --ms) _delay_ms(1);
        }
        if (strncmp_P(line, PSTR("BUSY"), 4) == 0) busy(atol(line + 4));
        SAY("ok");
    }
#elif defined(FAMILY_MARLIN) || defined(FAMILY_PRUSA)
    SAY("start");
    SAY("echo:Marlin 1.1.9");
    SAY("echo: Last Updated: 2018-08-01 | Author: (none, default config)");
    _delay_ms(2100); /* the SD card probe */
    SAY("echo:SD init fail");
    uint8_t checksum_failed = 0;
    for (;;) {
        read_line();
        if (strncmp_P(line, PSTR("M109"), 4) == 0) {
            for (uint8_t s = 0; s < 5; ++s) {
                _delay_ms(1000);
                SAY("echo:busy: processing");
            }
        } else if (strncmp_P(line, PSTR("G4 P"), 4) == 0) {
            SAY("ok");
            long left_ms = atol(line + 4);
            while (left_ms > 0) {
                const long slice = left_ms < 2000 ? left_ms : 2000;
                for (long ms = 0; ms < slice; ++ms) _delay_ms(1);
                left_ms -= slice;
                if (left_ms > 0) SAY("busy: processing");
            }
            continue;
        } else if (strcmp_P(line, PSTR("KILL")) == 0 || strcmp_P(line, PSTR("FATAL")) == 0) {
            if (line[0] == 'K') {
                SAY("Error:Printer halted. kill() called!");
            } else {
                SAY("fatal:Homing failed!");
            }
            for (;;) {
            }
        } else if (strstr_P(line, PSTR("*99")) != 0 && !checksum_failed) {
            checksum_failed = 1;
            SAY("Error:checksum mismatch, Last Line: 0");
            SAY("Resend: 1");
        } else if (!known_command()) {
#if defined(FAMILY_PRUSA)
            print_P(PSTR("Unknown "));
            put(line[0]);
            say_unknown(PSTR(" code: "), PSTR("\r\n"));
#else
            say_unknown(PSTR("echo:Unknown command: \""), PSTR("\"\r\n"));
#endif
        }
        SAY("ok");
    }
#elif defined(FAMILY_TEACUP)
    SAY("start");
    SAY("ok");
    uint8_t checksum_failed = 0;
    for (;;) {
        read_line();
        if (strcmp_P(line, PSTR("QUEUED_M116")) == 0) {
            SAY("ok");
            SAY("Waiting for target temp");
            for (uint8_t s = 0; s < 4; ++s) {
                _delay_ms(1000);
                SAY("Waiting for target temp");
            }
            continue;
        }
        if (strncmp_P(line, PSTR("M116"), 4) == 0) _delay_ms(5000);
        if (strstr_P(line, PSTR("*99")) != 0 && !checksum_failed) {
            checksum_failed = 1;
            SAY("rs N1 Expected checksum 17");
        } else if (!known_command()) {
            print_P(line[0] == 'G' ? PSTR("E: Bad G-code ") : PSTR("E: Bad M-code "));
            const char *n = line + 1;
            while (*n >= '0' && *n <= '9') put(*n++);
            print_P(PSTR("\r\n"));
        }
        SAY("ok");
    }
#elif defined(FAMILY_SPRINTER)
    SAY("start");
    uint8_t checksum_failed = 0;
    for (;;) {
        read_line();
        if (strstr_P(line, PSTR("*99")) != 0 && !checksum_failed) {
            checksum_failed = 1;
            SAY("Serial Error: Line Number is not Last Line Number+1, Last Line:0");
            SAY("Resend:1");
        } else if (!known_command()) {
            say_unknown(line[0] == 'G' ? PSTR("Unknown G-COM:") : PSTR("Unknown M-COM:"), PSTR("\r\n"));
        }
        SAY("ok");
    }
#elif defined(FAMILY_REPETIER)
    SAY("start");
    for (;;) {
        read_line();
        SAY("ok"); /* queued */
        _delay_ms(2); /* ... and run */
        if (!known_command()) say_unknown(PSTR("Unknown command:"), PSTR(" \r\n"));
    }
#else
#error "build with FAMILY_GRBL, _MARLIN, _PRUSA, _TEACUP, _SPRINTER or _REPETIER"
#endif
}
