// One run of a firmware on a bare MCU (no board): the ELF loaded, USART0's
// input and capture, pins traced, the VCD streamed, the timing profile, the
// summary and the verdict. `avrbench run ELF` without --board is this run;
// BoardRun is the same for a board.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mcu/Mcu.hpp"
#include "core/Time.hpp"
#include "trace/Recorder.hpp"
#include "trace/Timeline.hpp"
#include "trace/VcdWriter.hpp"
#include "run/BoardRun.hpp"

namespace avrbench {

struct McuRunOptions {
    std::string elf;
    std::string mcu_type;            // "" = from the ELF's .mmcu section
    std::uint32_t frequency_hz = 0;  // 0 = from the ELF's .mmcu section
    bool skip_idle_loops = true;
    bool predecoded_core = true;  // mcu/PredecodedCore.hpp; false: simavr's avr_run_one
    bool translate_blocks = true;  // mcu/BlockTranslator.hpp (on the predecoded core)
    Picoseconds duration_ps = 1000 * kPsPerMs;
    std::string duration_text = "1s";  // as the user wrote it, for messages
    bool until_sleep = false;          // stop at the first SLEEP (bounded by the duration)
    std::string uart_in;               // a file for USART0 ("" = none), read by read_uart_input
    std::function<std::string(const std::string& path)> read_uart_input;
    std::string uart_out;              // USART0's capture ("" = none)
    std::string vcd;
    VcdOptions vcd_layout;
    std::string trace, trace_only;     // as BoardRunOptions'; with a VCD the default is every pin and USART0
    std::string profile;               // the timing profile as JSON ("" = not collected)
    std::function<void(double fraction, double simulated_s)> on_progress;
};

class McuRun {
public:
    explicit McuRun(McuRunOptions options);
    ~McuRun();
    McuRun(const McuRun&) = delete;
    McuRun& operator=(const McuRun&) = delete;

    void run();
    RunVerdict verdict() const;
    std::vector<std::string> summary() const;
    Mcu& mcu() { return *mcu_; }
    const Timeline& timeline() const { return timeline_; }

private:
    McuRunOptions options_;
    std::unique_ptr<Mcu> mcu_;
    Timeline timeline_;
    Recorder recorder_{timeline_};
    Uart* uart0_ = nullptr;
    bool slept_ = false;
    double wall_s_ = 0;
    std::string gtkw_path_;
};

}  // namespace avrbench
