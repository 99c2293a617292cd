#include "trace/WaveformFiles.hpp"

#include <filesystem>

#include "trace/FstFile.hpp"
#include "trace/GtkwWriter.hpp"

namespace avrbench {

std::string with_extension(const std::string& path, const std::string& extension) {
    const auto slash = path.find_last_of('/');
    const auto dot = path.find_last_of('.');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) return path.substr(0, dot) + extension;
    return path + extension;
}

WaveformFiles::WaveformFiles(Timeline& timeline, std::string vcd_path, bool stream, const VcdOptions& layout,
                             std::vector<std::string> background_scopes)
    : timeline_(timeline),
      path_(std::move(vcd_path)),
      vcd_file_(is_fst_path(path_) ? vcd_for_fst(path_) : path_),
      stream_wanted_(stream && !path_.empty()),
      layout_(layout),
      background_scopes_(std::move(background_scopes)) {
    if (is_fst_path(path_)) (void)vcd2fst_program("--vcd " + path_);  // before the run, not after it
}

WaveformFiles::~WaveformFiles() = default;

void WaveformFiles::start() {
    if (stream_wanted_) stream_ = std::make_unique<VcdStream>(timeline_, vcd_file_, layout_);
}

void WaveformFiles::drain(Picoseconds now_ps) {
    if (stream_) stream_->drain(timeline_, now_ps > kSettleLagPs ? now_ps - kSettleLagPs : 0);
}

std::string WaveformFiles::finish(Cycle end_cycle, std::uint32_t clock_hz) {
    if (path_.empty()) return "";
    VcdOptions vcd_options = layout_;
    vcd_options.end_cycle = end_cycle;
    vcd_options.end_clock_hz = clock_hz;
    const VcdResult vcd = stream_ ? stream_->finish(timeline_, vcd_options) : write_vcd(timeline_, vcd_file_, vcd_options);
    if (vcd_file_ != path_) convert_vcd_to_fst(vcd_file_, path_, "--vcd " + path_);
    const std::string gtkw_path = with_extension(path_, ".gtkw");
    GtkwOptions gtkw_options;
    gtkw_options.buses = layout_.buses;
    gtkw_options.fit_end_time = vcd.end_time;
    gtkw_options.fit_timescale = vcd.timescale;
    // A window a laptop screen holds; the run fills the wave pane. gtkwave
    // 3.3 (Debian's) gives it about 930 of the 1400 pixels (measured with
    // its Tcl getWindowEndTime: a zoom for 1000 showed 287 of 310 ms), so
    // the zoom is for 900: the whole run, with a little room after it.
    gtkw_options.window_width = 1400;
    gtkw_options.window_height = 900;
    gtkw_options.fit_width_pixels = 900;
    gtkw_options.background_scopes = background_scopes_;
    // The save file names the dump relative to its own folder, which gtkwave
    // resolves from wherever it is started.
    std::error_code ec;
    const auto gtkw_folder = std::filesystem::absolute(gtkw_path, ec).parent_path();
    std::string dump = std::filesystem::relative(std::filesystem::absolute(path_, ec), gtkw_folder, ec).generic_string();
    if (ec || dump.empty()) dump = std::filesystem::absolute(path_, ec).string();
    write_gtkw(timeline_, gtkw_path, dump, gtkw_options);
    return gtkw_path;
}

}  // namespace avrbench
