#include "run/McuRun.hpp"

#include <cstdio>

#include "mcu/ElfImage.hpp"
#include "core/Errors.hpp"
#include "core/Format.hpp"
#include "core/InputFile.hpp"
#include "core/OutputFile.hpp"
#include "mcu/TimingProfile.hpp"
#include "core/UserStop.hpp"
#include "trace/WaveformFiles.hpp"

namespace avrbench {

McuRun::McuRun(McuRunOptions options) : options_(std::move(options)) {
    const ElfImage elf = ElfImage::load(options_.elf);
    RunFiles files;
    files.input(options_.elf, "the firmware ELF");
    if (!options_.uart_in.empty() && options_.uart_in != "-") files.input(options_.uart_in, "--uart-in");
    if (!options_.vcd.empty()) {
        files.output(options_.vcd, "--vcd");
        files.output(with_extension(options_.vcd, ".gtkw"), "--vcd's gtkwave save file");
    }
    if (!options_.uart_out.empty()) files.output(options_.uart_out, "--uart-out");
    if (!options_.profile.empty()) files.output(options_.profile, "--profile");
    files.check();
    if (!options_.read_uart_input) {
        options_.read_uart_input = [](const std::string& path) {
            return read_input_file(path, "--uart-in", kMaxUartInputBytes);
        };
    }
    std::string uart_in_bytes;
    if (!options_.uart_in.empty()) uart_in_bytes = options_.read_uart_input(options_.uart_in);

    McuOptions mcu_options;
    mcu_options.name = "mcu";
    mcu_options.mcu_type = options_.mcu_type;
    mcu_options.skip_idle_loops = options_.skip_idle_loops;
    mcu_options.predecoded_core = options_.predecoded_core;
    mcu_options.translate_blocks = options_.translate_blocks;
    if (options_.frequency_hz != 0) mcu_options.frequency_hz = options_.frequency_hz;
    mcu_ = std::make_unique<Mcu>(elf, mcu_options);
    if (!options_.profile.empty()) mcu_->enable_profile();
    const bool tracing = !options_.vcd.empty() || !options_.trace.empty() || !options_.trace_only.empty();
    // The default on one MCU is every pin; --trace only checks its names then.
    if (tracing && !options_.trace.empty()) trace_pins_option(recorder_, *mcu_, options_.trace, "--trace");
    if (tracing) {
        trace_pins_option(recorder_, *mcu_, options_.trace_only.empty() ? "all" : options_.trace_only, "--trace-only");
    }
    try {
        uart0_ = &mcu_->uart(0);
    } catch (const BadInput&) {
        if (!options_.uart_in.empty() || !options_.uart_out.empty()) throw;
    }
    if (uart0_ != nullptr && tracing && options_.trace_only.empty()) {
        recorder_.trace_uart_tx(*mcu_, *uart0_);
        recorder_.trace_uart_rx(*mcu_, *uart0_);
    }
    if (!uart_in_bytes.empty()) uart0_->send(uart_in_bytes);
}

McuRun::~McuRun() = default;

void McuRun::run() {
    Mcu& mcu = *mcu_;
    const Cycle end_cycle = cycle_at_ps(mcu, options_.duration_ps);
    WaveformFiles waveforms(timeline_, options_.vcd, true, options_.vcd_layout);
    waveforms.start();
    const auto wall_start = std::chrono::steady_clock::now();
    const auto after_slice = [&] {
        waveforms.drain(ps_at_cycle(mcu, mcu.cycle()));
        if (options_.on_progress) {
            options_.on_progress(static_cast<double>(mcu.cycle()) / static_cast<double>(end_cycle), mcu.seconds());
        }
    };
    if (options_.until_sleep) {
        slept_ = mcu.run_until_sleep(end_cycle, after_slice);
    } else {
        mcu.run_sliced(end_cycle, after_slice);
    }
    wall_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    if (!options_.uart_out.empty()) write_output_file(options_.uart_out, uart0_->transmitted_text(), "--uart-out");
    if (timeline_.overflowed()) throw BadInput(timeline_.overflow_message());
    gtkw_path_ = waveforms.finish(mcu.cycle(), mcu.frequency_hz());
    if (const TimingProfiler* profile = mcu.profile()) {
        write_output_file(options_.profile, "{\"mcus\": [" + profile->json() + "]}\n", "--profile");
    }
}

std::vector<std::string> McuRun::summary() const {
    const Mcu& mcu = *mcu_;
    std::vector<std::string> out;
    const double simulated_s = mcu.seconds();
    out.push_back(format_text("avrbench run: %s on %s at %.6g MHz", options_.elf.c_str(), mcu.mcu_type().c_str(),
                       mcu.frequency_hz() / 1e6));
    out.push_back(format_text("  simulated  %.6f s (%llu cycles)", simulated_s, static_cast<unsigned long long>(mcu.cycle())));
    out.push_back(format_text("  wall       %.3f s, real-time factor %.1fx", wall_s_, wall_s_ > 0 ? simulated_s / wall_s_ : 0.0));
    if (mcu.idle_jumps() != 0) {
        out.push_back(format_text("  idle skip  %llu jumps over %.6f s of idle-loop passes",
                           static_cast<unsigned long long>(mcu.idle_jumps()),
                           static_cast<double>(mcu.idle_cycles_skipped()) / mcu.frequency_hz()));
    }
    if (options_.until_sleep) {
        // A SLEEP with interrupts off halts the core: the run stopped there, not at the time limit.
        const char* why = slept_ ? "firmware executed SLEEP" : mcu.halted() ? "the core halted (below)" : "time limit";
        out.push_back(format_text("  stopped    %s", why));
    }
    if (mcu.halted()) out.push_back("  halted     " + mcu.halt_reason());
    if (uart0_ != nullptr) {
        out.push_back(format_text("  uart0      %zu bytes from firmware, %llu bytes to firmware", uart0_->transmitted().size(),
                           static_cast<unsigned long long>(uart0_->bytes_delivered())));
    }
    if (const TimingProfiler* profile = mcu.profile()) {
        for (const std::string& text : profile->summary_lines()) out.push_back("  profile    " + text);
    }
    for (const std::string& text : mcu.requested_reset_lines()) out.push_back("  reset      " + text);
    out.push_back(format_text("  findings   %zu", mcu.findings().size()));
    for (const auto& text : summarize_findings(mcu.findings())) out.push_back("    " + text);
    if (!options_.vcd.empty()) {
        out.push_back(format_text("  vcd        %s (%zu signals, %llu events), gtkwave save file %s", options_.vcd.c_str(),
                           timeline_.signals().size(), static_cast<unsigned long long>(timeline_.recorded_count()),
                           gtkw_path_.c_str()));
    }
    return out;
}

RunVerdict McuRun::verdict() const {
    using O = RunVerdict::Outcome;
    const Mcu& mcu = *mcu_;
    if (user_stop_requested()) {
        return {O::Interrupted, format_text("interrupted at %.6f s simulated; what was recorded is written", mcu.seconds())};
    }
    if (!mcu.findings().empty()) return {O::Finding, ""};
    if (options_.until_sleep && !slept_ && !mcu.halted()) {
        return {O::Timeout, "timeout: the firmware did not execute SLEEP within " + options_.duration_text};
    }
    return {O::Ok, ""};
}

}  // namespace avrbench
