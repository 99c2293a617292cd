/*
 * host_peer - the serial protocol of a printer/CNC firmware family, as its
 * documentation and sources describe it, without the machine behind it:
 * what the bench's UART host must cope with. USART0 at 115200 baud (U2X0,
 * UBRR0 = 16), polled. One build per family (-DFAMILY_GRBL/_MARLIN/_TEACUP).
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
 * Teacup: "start" and a boot "ok"; each line "ok"; "M116" waits 5 s in
 *   silence, then "ok".
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
#elif defined(FAMILY_MARLIN)
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
        }
        SAY("ok");
    }
#elif defined(FAMILY_TEACUP)
    SAY("start");
    SAY("ok");
    for (;;) {
        read_line();
        if (strncmp_P(line, PSTR("M116"), 4) == 0) _delay_ms(5000);
        SAY("ok");
    }
#else
#error "build with FAMILY_GRBL, FAMILY_MARLIN or FAMILY_TEACUP"
#endif
}
