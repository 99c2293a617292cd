// G-code to the binary records of seed 002's firmware (firmware/cnc2axis),
// as the thesis' PC program computes them (digest §4): step counts from the
// microstep size, timer compare values OCR = f / (2 N (v / microstep)) - 1
// per axis, the START byte of directions and enables, arcs cut into chords.
// The thesis-faithful form truncates OCR, sends 16-bit counts and G01 with
// X counted only; the improved form rounds OCR, sends 24-bit counts, a Y
// count in G01 and arc records with both axes' counts.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace avrbench {

struct RecordOptions {
    bool improved = false;
    double steps_per_mm = 160;        // seed 002: 0.2 mm / 32 microsteps
    double cpu_hz = 16e6;
    double prescaler = 1024;          // both step timers (digest §7.7)
    double rapid_mm_per_s = 48.828125;  // G00 at OCR 0: 16 MHz / (2 * 1024) / 160
    double chord_deg = 5;             // arcs: at most this angle per chord (R = 20 mm: 19 um chord error)
};

struct RecordProgram {
    // One message per acknowledgement: a command with its payload, or one
    // arc record (the arc's command byte goes with its first record).
    std::vector<std::string> messages;
    // How long each message keeps the firmware busy before its ACK (the
    // move's step count at its timer's rate; 0 for an arc record, ACKed
    // when it is loaded): a host's ACK timeout must allow for it.
    std::vector<double> busy_seconds;
    unsigned moves = 0, arcs = 0, chords = 0;
};

// `gcode`: "G00/G01/G02/G03 X.. Y.. [I.. J..] [F..]" lines in absolute mm
// from home (as emit_gcode writes them), F in mm/min, M30 at the end. Throws
// BadInput "<where>:<line>: ..." for a line it cannot convert.
RecordProgram records_from_gcode(const std::string& gcode, const RecordOptions& options, const std::string& where);

}  // namespace avrbench
