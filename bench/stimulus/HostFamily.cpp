#include "stimulus/HostFamily.hpp"

#include "core/GcodeLexer.hpp"

#include <cctype>
#include <cstring>

#include "core/Errors.hpp"

namespace avrbench {

namespace {

constexpr FirmwareFamily kFamilies[] = {FirmwareFamily::Generic,  FirmwareFamily::Grbl,     FirmwareFamily::Marlin,
                                        FirmwareFamily::Teacup,   FirmwareFamily::Repetier, FirmwareFamily::Sprinter,
                                        FirmwareFamily::Prusa};

bool starts(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

bool starts_ci(std::string_view s, std::string_view prefix) {
    if (s.size() < prefix.size()) return false;
    for (std::size_t i = 0; i < prefix.size(); ++i) {
        if (std::tolower(static_cast<unsigned char>(s[i])) != std::tolower(static_cast<unsigned char>(prefix[i]))) return false;
    }
    return true;
}

// "ok", "ok T:...", Repetier's "ok 12": not "okay".
bool is_ok(std::string_view s) { return starts(s, "ok") && (s.size() == 2 || !std::isalpha(static_cast<unsigned char>(s[2]))); }

// A firmware that stopped for good: "!!" (Teacup, Repetier, Marlin 2's
// host protocol), "fatal:" in any case (Repetier's GCode::fatalError),
// Marlin's kill() "Error:Printer halted. kill() called!" (it answers
// nothing after it).
bool is_fatal(std::string_view s) { return starts(s, "!!") || starts_ci(s, "fatal:") || starts_ci(s, "error:printer halted"); }

}  // namespace

const char* to_string(FirmwareFamily family) {
    switch (family) {
        case FirmwareFamily::Generic: return "generic";
        case FirmwareFamily::Grbl: return "grbl";
        case FirmwareFamily::Marlin: return "marlin";
        case FirmwareFamily::Teacup: return "teacup";
        case FirmwareFamily::Repetier: return "repetier";
        case FirmwareFamily::Sprinter: return "sprinter";
        case FirmwareFamily::Prusa: return "prusa";
    }
    return "?";
}

const char* firmware_family_names() { return "generic, grbl, marlin, teacup, repetier, sprinter or prusa"; }

FirmwareFamily parse_firmware_family(std::string_view text, std::string_view what) {
    for (FirmwareFamily f : kFamilies) {
        if (text == to_string(f)) return f;
    }
    throw BadInput(std::string(what) + ": firmware family '" + std::string(text) + "' is not " + firmware_family_names());
}

double default_line_timeout_s(FirmwareFamily family) {
    switch (family) {
        case FirmwareFamily::Marlin:
        case FirmwareFamily::Prusa:
        case FirmwareFamily::Repetier: return 5.0;
        case FirmwareFamily::Teacup: return 2.5;
        case FirmwareFamily::Grbl:
        case FirmwareFamily::Sprinter:
        case FirmwareFamily::Generic: return 2.0;
    }
    return 2.0;
}

FamilyArcs family_arcs(FirmwareFamily family) {
    switch (family) {
        case FirmwareFamily::Grbl: return {0.002, 0};  // grbl defaults.h: DEFAULT_ARC_TOLERANCE 0.002 (mm)
        case FirmwareFamily::Marlin:                    // Marlin 1.0 Configuration_adv.h: MM_PER_ARC_SEGMENT 1
        case FirmwareFamily::Prusa:                     // (Marlin 1.1 and Prusa-Firmware keep it)
        case FirmwareFamily::Sprinter:                  // Sprinter Configuration.h: MM_PER_ARC_SEGMENT 1
        case FirmwareFamily::Repetier: return {0, 1.0};  // Repetier.h: MM_PER_ARC_SEGMENT 1
        case FirmwareFamily::Teacup:                     // no G2/G3 ("E: Bad G-code 2")
        case FirmwareFamily::Generic: return {};
    }
    return {};
}

const char* welcome_text(FirmwareFamily family) { return family == FirmwareFamily::Grbl ? "Grbl X.Y" : "start"; }

const char* to_string(AnswerKind kind) {
    switch (kind) {
        case AnswerKind::Text: return "text";
        case AnswerKind::Welcome: return "welcome";
        case AnswerKind::Ok: return "ok";
        case AnswerKind::Error: return "error";
        case AnswerKind::ErrorNote: return "error-note";
        case AnswerKind::Resend: return "resend";
        case AnswerKind::ResendError: return "resend-error";
        case AnswerKind::Alarm: return "alarm";
        case AnswerKind::Fatal: return "fatal";
    }
    return "?";
}

AnswerKind classify_answer(FirmwareFamily family, std::string_view s) {
    switch (family) {
        case FirmwareFamily::Grbl:
            // grbl 1.1 (doc/markdown/interface.md): "Grbl 1.1h ['$' for help]";
            // '>' startup-line results (">G54:ok", ">:error:7"), [MSG:..],
            // [GC:..] and <status> answer no line; "error:N" replaces the ok.
            if (starts(s, "Grbl ")) return AnswerKind::Welcome;
            if (starts(s, ">") || starts(s, "[") || starts(s, "<")) return AnswerKind::Text;
            if (is_ok(s)) return AnswerKind::Ok;
            if (starts(s, "error")) return AnswerKind::Error;
            if (starts(s, "ALARM")) return AnswerKind::Alarm;
            return AnswerKind::Text;
        case FirmwareFamily::Marlin:
        case FirmwareFamily::Prusa:
            // Marlin 1.0/1.1 (Marlin_main.cpp): "start"; "Error:" (checksum,
            // line number) then "Resend: N" and "ok"; an unknown command
            // `echo:Unknown command: "M9999"` then "ok". Prusa-Firmware adds
            // "Unknown G code: G5 X1" (MSG_UNKNOWN_CODE, "Unknown %c code: %s")
            // before its ok.
            if (s == "start") return AnswerKind::Welcome;
            if (is_fatal(s)) return AnswerKind::Fatal;
            if (starts(s, "echo:Unknown command")) return AnswerKind::ErrorNote;
            if (family == FirmwareFamily::Prusa && starts(s, "Unknown ") && s.find(" code: ") == 9) return AnswerKind::ErrorNote;
            if (starts(s, "Resend:")) return AnswerKind::Resend;
            if (is_ok(s)) return AnswerKind::Ok;
            if (starts(s, "Error") || starts(s, "error")) return AnswerKind::ErrorNote;
            return AnswerKind::Text;
        case FirmwareFamily::Teacup:
            // Teacup (gcode_process.c, gcode_parse.c, mendel.c): "start" and a
            // boot "ok"; "E: Bad G-code 5" / "E: Bad M-code 123" before the ok
            // every line gets; "rs N12 Expected checksum 56" (then the ok)
            // asks for the line again.
            if (s == "start") return AnswerKind::Welcome;
            if (is_fatal(s)) return AnswerKind::Fatal;
            if (starts(s, "rs ")) return AnswerKind::ResendError;
            if (is_ok(s)) return AnswerKind::Ok;
            if (starts(s, "E:")) return AnswerKind::ErrorNote;
            return AnswerKind::Text;
        case FirmwareFamily::Sprinter:
            // Sprinter (Sprinter.pde): "start"; "Serial Error: Line Number is
            // not Last Line Number+1" and "Error: checksum mismatch" then
            // "Resend:N" and "ok"; "Unknown G-COM:", "Unknown M-COM:" (with
            // SEND_WRONG_CMD_INFO) and "Unknown command:" before the ok.
            if (s == "start") return AnswerKind::Welcome;
            if (is_fatal(s)) return AnswerKind::Fatal;
            if (starts(s, "Resend:")) return AnswerKind::Resend;
            if (is_ok(s)) return AnswerKind::Ok;
            if (starts(s, "Serial Error:") || starts(s, "Error") || starts(s, "Unknown G-COM:") ||
                starts(s, "Unknown M-COM:") || starts(s, "Unknown command:")) {
                return AnswerKind::ErrorNote;
            }
            return AnswerKind::Text;
        case FirmwareFamily::Repetier:
            // Repetier 1.0 (gcode.cpp, Commands.cpp, Communication.cpp):
            // "start"; "ok" (or "ok N") when a line is queued, so
            // "Unknown command:N12 M9999 " comes when it runs, after its ok;
            // "Resend:N" then "ok"; "Error:..." reports; "fatal:..." stops;
            // "wait" every second while idle, "skip N" for a line seen twice.
            if (s == "start") return AnswerKind::Welcome;
            if (is_fatal(s)) return AnswerKind::Fatal;
            if (starts(s, "Resend:")) return AnswerKind::Resend;
            if (is_ok(s)) return AnswerKind::Ok;
            if (starts(s, "Unknown command:") || starts(s, "Error:")) return AnswerKind::ErrorNote;
            return AnswerKind::Text;
        case FirmwareFamily::Generic:
            // Nothing assumed but the common words: "ok" answers a line,
            // "error..." answers it refusing it, "ALARM" stops the machine,
            // "!!"/"fatal:" stop the firmware.
            if (is_fatal(s)) return AnswerKind::Fatal;
            if (is_ok(s)) return AnswerKind::Ok;
            if (starts(s, "error") || starts(s, "Error")) return AnswerKind::Error;
            if (starts(s, "ALARM")) return AnswerKind::Alarm;
            return AnswerKind::Text;
    }
    return AnswerKind::Text;
}

bool is_busy_report(FirmwareFamily family, std::string_view s) {
    switch (family) {
        case FirmwareFamily::Marlin:
        case FirmwareFamily::Prusa: return starts(s, "echo:busy:") || starts(s, "busy:");
        case FirmwareFamily::Repetier: return starts(s, "busy:");
        case FirmwareFamily::Teacup: return starts(s, "Waiting for target temp");
        case FirmwareFamily::Grbl: return starts(s, "<") && !starts(s, "<Idle");
        case FirmwareFamily::Sprinter:
        case FirmwareFamily::Generic: return false;
    }
    return false;
}

namespace {

// The first word of letter G, M, T or D with a number: "G5", or "G-code 5"
// as Teacup spells it. Digits only, no leading zeros kept ("G01" is "G1").
std::string first_command(std::string_view s, bool allow_code_spelling) {
    for (std::size_t i = 0; i < s.size(); ++i) {
        const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(s[i])));
        if (letter != 'G' && letter != 'M' && letter != 'T' && letter != 'D') continue;
        // A word starts a token: not the 'm' of "command" nor the 'd' of "Bad".
        if (i > 0 && std::isalnum(static_cast<unsigned char>(s[i - 1]))) continue;
        std::size_t j = i + 1;
        if (allow_code_spelling && s.substr(j, 6) == "-code ") j += 6;
        while (j < s.size() && s[j] == ' ') ++j;
        std::size_t k = j;
        while (k < s.size() && std::isdigit(static_cast<unsigned char>(s[k]))) ++k;
        if (k == j) continue;
        while (j + 1 < k && s[j] == '0') ++j;
        return std::string(1, letter) + std::string(s.substr(j, k - j));
    }
    return "";
}

}  // namespace

std::string command_named(std::string_view error_line) {
    // Skip the family's own prefix words ("echo:Unknown command:", "E: Bad"):
    // they hold no digits, so the first lettered number is the command.
    return first_command(error_line, true);
}

std::string command_word(std::string_view gcode_line) {
    // Past a line number "N12 " and before a checksum or comment: the first
    // G, M, T or D word, its whole digits without leading zeros.
    for (const GcodeWord& w : lex_lenient_gcode(gcode_line)) {
        if (w.letter != 'G' && w.letter != 'M' && w.letter != 'T' && w.letter != 'D') continue;
        // A word starts a token: not the 'd' of "Bad".
        if (w.begin > 0 && std::isalnum(static_cast<unsigned char>(gcode_line[w.begin - 1]))) continue;
        std::size_t j = w.begin + 1;
        while (j < w.end && gcode_line[j] == ' ') ++j;
        std::size_t k = j;
        while (k < w.end && std::isdigit(static_cast<unsigned char>(gcode_line[k]))) ++k;
        if (k == j) continue;
        while (j + 1 < k && gcode_line[j] == '0') ++j;
        return std::string(1, w.letter) + std::string(gcode_line.substr(j, k - j));
    }
    return "";
}

}  // namespace avrbench
