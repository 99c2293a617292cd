// A run's waveform files: the VCD and, beside it, a gtkwave save file zoomed
// to the whole run, with the board's names first and the MCUs' raw pins last
// (GtkwOptions::background_scopes). Every front end writes them this way: the
// CLI's `run --vcd`, `check --vcd-dir`, the C++ API.
//
// The VCD is written as the run goes (VcdStream: memory does not grow with
// the run's length) when `stream` is set, else at the end from the timeline
// in memory (when a report needs the whole timeline anyway). A path ending
// in .fst gets an FST file instead (trace/FstFile.hpp: the VCD written
// beside it, converted at the end).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/Time.hpp"
#include "trace/Timeline.hpp"
#include "trace/VcdWriter.hpp"

namespace avrbench {

class WaveformFiles {
public:
    // Events may be recorded up to one UART frame after the time they stamp
    // (a byte is stamped with its start bit): 100 ms covers frames down to
    // 100 baud. A streamed dump is written up to this far behind the run.
    static constexpr Picoseconds kSettleLagPs = 100 * kPsPerMs;

    // `layout`: the VCD's buses and alias codes (VcdOptions; its end is
    // given to finish()). `background_scopes`: scopes whose pins go last,
    // collapsed, in the save file (a board's MCUs).
    WaveformFiles(Timeline& timeline, std::string vcd_path, bool stream, const VcdOptions& layout = {},
                  std::vector<std::string> background_scopes = {});
    ~WaveformFiles();
    WaveformFiles(const WaveformFiles&) = delete;
    WaveformFiles& operator=(const WaveformFiles&) = delete;

    // Once every signal is registered (the header lists them).
    void start();
    // Hands the dump what was recorded up to `now_ps` less the settle lag.
    void drain(Picoseconds now_ps);
    // Writes the rest (or all), ending the dump at `end_cycle` of a
    // `clock_hz` clock, and the save file; returns the save file's path.
    std::string finish(Cycle end_cycle, std::uint32_t clock_hz);

    const std::string& vcd_path() const { return path_; }

private:
    Timeline& timeline_;
    std::string path_;      // what the user asked for: a .vcd or an .fst
    std::string vcd_file_;  // where the VCD goes (path_, or beside an .fst)
    bool stream_wanted_;
    VcdOptions layout_;
    std::vector<std::string> background_scopes_;
    std::unique_ptr<VcdStream> stream_;
};

// `path` with its extension (after the last dot of its file name) replaced.
std::string with_extension(const std::string& path, const std::string& extension);

}  // namespace avrbench
