// What a printer or CNC firmware family says on its serial port, read from
// each firmware's own sources (docs/HOSTS.md, "Answers by family", quotes
// each line's origin): its welcome, the output that answers no line, and
// how it answers a line - ok, an error, a request to send it again, an
// alarm, a fatal stop. The UART host (stimulus/UartHost) streams by it; the
// table lives here so that a new family is one entry in one file.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace avrbench {

enum class FirmwareFamily { Generic, Grbl, Marlin, Teacup, Repetier, Sprinter, Prusa };

const char* to_string(FirmwareFamily family);
// "generic", "grbl", "marlin", "teacup", "repetier", "sprinter", "prusa";
// BadInput naming `what` otherwise.
FirmwareFamily parse_firmware_family(std::string_view text, std::string_view what);
// Every family's name, for option help and messages ("generic, grbl, ...").
const char* firmware_family_names();

// A family's line timeout: 2.5 times the longest keep-alive period its
// firmware documents, so a keep-alive arriving on time never races it.
//   marlin, prusa  5 s: busy: every DEFAULT_KEEPALIVE_INTERVAL = 2 s
//                  (HOST_KEEPALIVE_FEATURE, Marlin's Configuration_adv.h)
//   repetier       5 s: "busy:processing" every 2 s (KEEP_ALIVE_INTERVAL 2000)
//   teacup         2.5 s: "Waiting for target temp" every second while M116 waits
//   grbl           2 s: the host's own '?' every 250 ms brings a report (assumed)
//   sprinter, generic  2 s (assumed: no keep-alives known)
double default_line_timeout_s(FirmwareFamily family);

// What one line the firmware printed is, in its family's protocol.
enum class AnswerKind {
    Text,         // anything else: reports, messages, keep-alives (transcript only)
    Welcome,      // what the firmware prints first after a reset
    Ok,           // answers the oldest unanswered line
    Error,        // answers the oldest unanswered line, refusing it (grbl's error:N)
    ErrorNote,    // an error about a line whose answer ("ok", or a resend) follows or came before
    Resend,       // "send the oldest line again": the "ok" that follows means ready, not done
    ResendError,  // an error that is also a resend request (Teacup's "rs N...")
    Alarm,        // grbl's ALARM:N - the machine stopped
    Fatal,        // the firmware stopped for good ("!!", "fatal:", kill())
};
const char* to_string(AnswerKind kind);

// How `line` (without its line end) reads for `family`.
AnswerKind classify_answer(FirmwareFamily family, std::string_view line);

// A line by which the firmware says it is still working on something (a
// keep-alive while it waits or moves): Marlin's and Prusa's "echo:busy:
// processing" (HOST_KEEPALIVE_FEATURE), Repetier's "busy:processing",
// Teacup's "Waiting for target temp" (M116, clock.c), grbl's status report
// in any state but Idle ("<Run|...>"). A run is not done while they come.
bool is_busy_report(FirmwareFamily family, std::string_view line);

// The command an error line names, as its first G/M/T/D word ("M9999" from
// `echo:Unknown command: "M9999"`, "G5" from Teacup's `E: Bad G-code 5`),
// upper case, or "" when it names none.
std::string command_named(std::string_view error_line);
// A line's own first G/M/T/D word ("G1" of "N12 G1 X10*91"), "" for none.
std::string command_word(std::string_view gcode_line);

// How the family's firmware draws G2/G3 arcs by default: chords within
// `tolerance_mm` of the circle (grbl's $12), or segments `segment_mm` long
// (MM_PER_ARC_SEGMENT); both 0 where it draws none or is unknown.
struct FamilyArcs {
    double tolerance_mm = 0;
    double segment_mm = 0;
};
FamilyArcs family_arcs(FirmwareFamily family);

// The family's welcome as messages show it ("Grbl X.Y", "start").
const char* welcome_text(FirmwareFamily family);

}  // namespace avrbench
