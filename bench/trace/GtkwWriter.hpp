// Writes a gtkwave save file (.gtkw) that opens a VcdWriter dump with every
// signal already on screen: one collapsible group per scope (named after it),
// buses in hex, reals as analog step plots.
//
// The trace flags are gtkwave's TR_* bits (gtkwave's savefile/analyzer headers;
// the numbers below are what gtkwave 3.3.118 itself writes for these traces):
//   @28       TR_BIN|TR_RJUSTIFY              a 1-bit wire, gtkwave's default
//   @22       TR_HEX|TR_RJUSTIFY              a bus shown in hex
//   @8028     TR_ANALOG_STEP|TR_BIN|TR_RJUSTIFY  a real as an analog step plot
//   @20000    TR_ANALOG_BLANK_STRETCH         one extra row of height for the plot above
//   @800200   TR_GRP_BEGIN|TR_BLANK           opens a group (the "-name" line names it)
//   @1000200  TR_GRP_END|TR_BLANK             closes it
// The content is deterministic: no date, sizes or paths besides the dump's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "trace/Timeline.hpp"
#include "trace/VcdWriter.hpp"

namespace avrbench {

struct GtkwOptions {
    // How the dump holds buses (VcdOptions::buses): written as bits, each bus
    // is joined back into one trace ("#{scope.name[7:0]} scope.name[7] ...").
    VcdBuses buses = VcdBuses::Bits;
    unsigned analog_extra_rows = 3;  // height of each real's plot beyond its own row
    bool groups_closed = false;      // start with groups collapsed (@c00200)
    // When non-zero: open zoomed so the dump's 0..fit_end_time (in units of
    // the VCD's `fit_timescale`, e.g. VcdResult::end_time and ::timescale)
    // fills about fit_width_pixels of the default window's wave pane.
    // gtkwave 3.3.118 reads the "*<zoom>" line as: time per pixel =
    // 2^-zoom / 192 in the timescale's unit (ps for "100ps"); measured on
    // screenshots at zoom 0, -10, -20 and -32 with 100 ps and 1 fs dumps.
    std::uint64_t fit_end_time = 0;
    std::string fit_timescale = "1ps";
    unsigned fit_width_pixels = 550;
    // The window gtkwave opens ("[size]"; 0: gtkwave's default, 870 x 560).
    unsigned window_width = 0;
    unsigned window_height = 0;
    // Scopes whose pins (1-bit wires) are shown last, collapsed, as "<scope>
    // pins" (a board's MCUs), after the net and label names and the parts;
    // their other signals (USART and TWI bytes) stay in an open group.
    std::vector<std::string> background_scopes;
};

// `dump_path` is written as given into [dumpfile]. gtkwave opens it relative to
// its working directory; when that fails it resolves it relative to the save
// file's own directory, using the [savefile] entry written from
// `save_file_name` (the .gtkw's file name without directories; empty: none).
// So a dump path relative to the .gtkw's directory works from anywhere.
// Throws std::invalid_argument when a name contains '"' or a line break (the
// format has no escape for them).
std::string format_gtkw(const Timeline& timeline, const std::string& dump_path, const std::string& save_file_name,
                        const GtkwOptions& options = {});

// Writes format_gtkw(timeline, dump_path, <file name of gtkw_path>, options).
// Throws std::runtime_error naming `gtkw_path` when it cannot be written.
void write_gtkw(const Timeline& timeline, const std::string& gtkw_path, const std::string& dump_path,
                const GtkwOptions& options = {});

}  // namespace avrbench
