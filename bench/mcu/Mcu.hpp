// One simavr MCU (RAII): firmware loaded, virtual time, named pins, UARTs, a
// scheduler, and the crash oracles checked after every instruction.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "periph/memory/BootSection.hpp"
#include "mcu/ElfImage.hpp"
#include "core/AvrContext.hpp"
#include "core/Finding.hpp"
#include "periph/timer/PeriodicOutput.hpp"
#include "periph/ports/Pin.hpp"
#include "core/Scheduler.hpp"
#include "periph/SimavrFixes.hpp"
#include "core/SimavrLog.hpp"
#include "periph/spi/Spi.hpp"
#include "periph/usart/Uart.hpp"
#include "core/Time.hpp"

struct avr_t;
struct avr_io_t;
struct avr_extint_t;
struct avr_acomp_t;

namespace avrbench {

class Adc;
class DebugHook;
class IdleLoopSkipper;
class PredecodedCore;
class TimingProfiler;
class WatchdogWatch;
class Mcu;
class Twi;

struct McuOptions {
    std::string name = "mcu";        // the MCU's name on the board, used in scopes and findings
    std::string mcu_type;            // overrides the ELF's .mmcu section, e.g. "atmega328p"
    std::uint32_t frequency_hz = 0;  // overrides the ELF's .mmcu section
    // Step the way simavr's avr_callback_run_raw does, every cycle timer
    // processed on every step, with none of Mcu::run_until's fast paths
    // (SimavrStepper::reference_step; tests prove the two end in the same state).
    bool reference_run_loop = false;
    // Jump over the passes of an idle loop up to the next event
    // (mcu/IdleLoopSkip.hpp); exact, so on unless a test compares without.
    // The reference run loop never skips.
    bool skip_idle_loops = true;
    // Execute instructions on mcu/PredecodedCore (decoded once per flash
    // word; proven to do what simavr's avr_run_one does) or, with false, on
    // avr_run_one itself (`--simavr-core`; kept selectable for one release).
    // The reference run loop always uses avr_run_one.
    bool predecoded_core = true;
    // On the predecoded core, run straight runs of
    // instructions as host code (mcu/BlockTranslator.hpp; x86-64 hosts).
    // Exact like the rest of the core; off only to measure or compare.
    bool translate_blocks = true;
    // Fuse bytes low, high, extended (e.g. an UNO's 0xFF, 0xDE, 0xFD);
    // replace the ELF's .fuse section when given.
    std::optional<std::array<std::uint8_t, 3>> fuses;
    // The lock byte (e.g. 0x0F, as the Arduino IDE burns with a boot loader);
    // replaces the ELF's .lock section. Without either: 0xFF, nothing locked.
    std::optional<std::uint8_t> lock_bits;
    // A boot loader (Intel HEX, e.g. Debian's optiboot_atmega328.hex) put in
    // the boot section the fuses' BOOTSZ bits select; with BOOTRST
    // programmed the MCU starts there (periph/memory/BootSection.hpp). Needs `fuses`.
    std::string bootloader_hex;
    // Every watchdog reset is expected (the board says so: a firmware that
    // resets itself by design), none a finding. Otherwise a reset is a
    // finding unless the firmware asked for it (periph/watchdog/WatchdogWatch.hpp).
    bool watchdog_resets_expected = false;
};

enum class StopReason {
    ReachedTarget,   // the requested cycle was reached
    Requested,       // a callback called request_stop()
    Halted,          // the MCU can run no further (finding, crash, sleep with interrupts off)
};

// What keeps several MCUs of a board in step (mcu/Lockstep.hpp): told when
// something outside an MCU is about to change what that MCU sees.
class PeerSync {
public:
    virtual ~PeerSync() = default;
    virtual void reach(Mcu& mcu) = 0;
};

// AFL-style edge coverage of the firmware (bench/fuzz): each instruction's
// PC with the previous one, hashed into a map of saturating counters.
struct PcEdgeMap {
    std::uint8_t* counters = nullptr;
    std::uint32_t mask = 0;  // map size - 1 (a power of two)
    std::uint32_t previous = 0;
    // Counters that reached 1, 2, 3, 4, 8, ... 128: each is a feature new to
    // libFuzzer's hit-count buckets (1, 2, 3, 4-7, 8-15, 16-31, 32-127, 128+;
    // 64 counted too), so a run that stops adding them only repeats itself.
    std::uint64_t features = 0;
    // Inlined into the covering batch's handlers (called out of line it cost 7 %).
    [[gnu::always_inline]] void hit(std::uint32_t pc_bytes) {
        const std::uint32_t location = pc_bytes >> 1;
        std::uint8_t& counter = counters[(location ^ previous) & mask];
        if (counter != 0xFF) {
            const unsigned count = ++counter;
            features += static_cast<unsigned>((count & (count - 1)) == 0) | static_cast<unsigned>(count == 3);
        }
        previous = location >> 1;  // shifted, so A->B and B->A differ
    }
};

class Mcu final : private SimavrLogSink {
public:
    // Throws BadInput (one line) when the MCU type or clock is unknown or
    // missing (an ELF without .mmcu section and no override).
    Mcu(const ElfImage& elf, McuOptions options = {});
    ~Mcu();
    Mcu(const Mcu&) = delete;
    Mcu& operator=(const Mcu&) = delete;

    const std::string& name() const { return options_.name; }
    const std::string& mcu_type() const { return mcu_type_; }
    std::uint32_t frequency_hz() const { return frequency_hz_; }
    const ElfImage& elf() const { return elf_; }
    avr_t* avr() const { return avr_; }
    // The predecoded instruction core, nullptr on avr_run_one (McuOptions::predecoded_core).
    const PredecodedCore* predecoded_core() const { return predecoded_.get(); }

    // Inline (the lockstep asks each MCU its cycle several times per turn):
    // a pointer to simavr's own counter, set when the core is made.
    Cycle cycle() const { return *cycle_; }
    std::uint32_t pc_bytes() const;
    std::uint16_t stack_pointer() const;
    double seconds() const { return static_cast<double>(cycle()) / frequency_hz_; }
    Cycle cycles_from_seconds(double seconds) const;

    bool sleeping() const;
    // The core stopped: a finding halted it, simavr crashed it, or it slept with
    // interrupts disabled (nothing can wake it).
    bool halted() const { return halted_; }
    const std::string& halt_reason() const { return halt_reason_; }

    // Runs until the cycle counter reaches `target_cycle`, the MCU halts, or a
    // callback asks to stop. A sleeping core jumps straight to its next event.
    StopReason run_until(Cycle target_cycle);
    StopReason run_for(Cycle cycles) { return run_until(cycle() + cycles); }
    // run_until, recording every instruction's PC edge in `edges` (fuzzing).
    StopReason run_until_covering(Cycle target_cycle, PcEdgeMap& edges);
    // From now on every run_until covers into `edges` (nullptr: no longer),
    // also when a board's lockstep drives this MCU among others (fuzzing a
    // multi-MCU board through one of them).
    void set_run_coverage(PcEdgeMap* edges) { run_coverage_ = edges; }
    // Collects the timing profile (mcu/TimingProfile.hpp) from now on;
    // every instruction then takes the run loop's general step.
    void enable_profile();
    // nullptr until enable_profile().
    const TimingProfiler* profile() const { return profiler_.get(); }
    // A debugger (mcu/DebugHook.hpp); nullptr detaches. Idle loops are not
    // skipped while one is attached: it may stop in front of any instruction.
    void set_debug_hook(DebugHook* hook);
    DebugHook* debug_hook() const { return debug_; }
    // Executes one instruction (or one sleep fast-forward). Returns false once halted.
    bool step();
    void request_stop();
    // Ends the present run_until after this instruction with ReachedTarget
    // (the lockstep takes its turn again: another MCU's horizon changed).
    void request_yield();
    bool in_run() const { return in_run_; }
    // Asleep with no interrupt on its way: nothing changes until its next
    // cycle timer, unless something outside wakes it.
    bool dormant() const { return *state_ == kCpuSleeping && no_pending_interrupts(); }
    // Whether a level change on `pin` can make an interrupt pending with the
    // registers as they are now (INTn or PCINTn enabled for it, the analog
    // comparator's interrupt or input capture on, or a peripheral input such
    // as RxD, ICPn, Tn, SPI or TWI: McuPins' table). The lockstep lets other
    // cores run past a dormant MCU's present when no change they can make
    // would wake it. Conservative: true for an MCU type the table does not know.
    bool pin_change_may_interrupt(const Pin& pin) const {
        return pin_feeds_a_peripheral(pin) || pin_interrupt_enabled(pin);
    }
    // The part that does not depend on the registers: the pin is an input of
    // a peripheral that can interrupt (or the MCU type's pins are not known).
    bool pin_feeds_a_peripheral(const Pin& pin) const;
    // The part that does: INTn or PCINTn enabled for the pin, or the analog
    // comparator's interrupt or input capture trigger on.
    bool pin_interrupt_enabled(const Pin& pin) const;
    // The first pending cycle timer (simavr's peripherals, the scheduler's
    // events), or the largest cycle when none is pending.
    Cycle next_event_cycle() const;
    // The board's lockstep, told before a net or the TWI bus changes what
    // this MCU sees (it brings this MCU up to the running one's time).
    void set_peer_sync(PeerSync* sync) { peer_sync_ = sync; }
    void before_external_change() {
        if (peer_sync_ != nullptr) peer_sync_->reach(*this);
    }
    // The command line's runs: to `end_cycle` in slices of at most 10 ms
    // simulated, calling `after_slice` after each (progress, streaming a VCD),
    // until halted or SIGINT/SIGTERM (core/UserStop.hpp); or the same slices
    // until the firmware executes SLEEP (true: stopped right after it, before
    // the sleep jump) or the end comes.
    StopReason run_sliced(Cycle end_cycle, const std::function<void()>& after_slice);
    bool run_until_sleep(Cycle end_cycle, const std::function<void()>& after_slice = {});

    // "PB5" (also "B5"). Throws BadInput for a port the MCU does not have.
    Pin& pin(std::string_view name);
    // Who takes `pin` as a periodic wave when a timer's compare output
    // repeats on it (periph/timer/PeriodicOutput.hpp); nullptr removes the sink
    // without ending a running wave (for teardown).
    // False when the bench does not model this MCU's timers.
    bool set_periodic_output_sink(Pin& pin, PeriodicOutputSink* sink);
    // Ends every running wave, so that PINx, the pins' IRQs and their nets
    // show the levels of now (for looking at the raw I/O space between runs;
    // the firmware's own reads end them anyway). They begin again at the
    // next period start.
    void settle_periodic_outputs();
    // USART n. Throws BadInput when the MCU has no such USART.
    Uart& uart(int index = 0);
    Scheduler& scheduler() { return *scheduler_; }
    // The TWI (I2C) module, or nullptr when the bench does not model the MCU's.
    Twi* twi() { return twi_.get(); }
    // The SPI master as the bench's SPI slave parts see it (periph/spi/Spi.hpp),
    // made on first use; nullptr when the part has no SPI.
    Spi* spi();
    // The ADC: analog sources per channel, pin -> channel (periph/adc/Adc.hpp).
    Adc& adc() { return *adc_; }

    const std::vector<Finding>& findings() const { return findings_.all(); }
    // The I/O register (data address) holding PUD, the pull-up disable bit
    // (MCUCR or SFIOR by family); 0 for a part without one.
    std::uint16_t pud_register() const;
    // Whether the instruction at `pc_before` left SP half written (avr-gcc's
    // `out SPH; out SREG; out SPL`: between them SP reads new-high/old-low).
    bool sp_half_written_by(std::uint32_t pc_before) const;
    // The firmware's own failures, which the core's oracles find (errors: they fail every run).
    static const FindingKind kSimavrCrash;       // simavr stopped the core (e.g. a write outside RAM)
    static const FindingKind kInvalidOpcode;     // an opcode the AVR core does not decode
    static const FindingKind kPcOutsideProgram;  // PC left the loaded program
    static const FindingKind kStackOverflow;     // SP went below the end of .data/.bss/.noinit
    static const FindingKind kBadInterrupt;      // an enabled interrupt without a handler
    static const FindingKind kWatchdogReset;     // the watchdog reset the MCU
    static const FindingKind kJumpToReset;       // execution reached the reset vector without a reset
    // Number of avr_run() steps taken: instructions plus sleep fast-forwards.
    std::uint64_t steps() const { return steps_; }
    // Switches idle-loop skipping on or off (McuOptions::skip_idle_loops).
    void set_skip_idle_loops(bool on);
    // McuOptions::predecoded_core after construction (not during a run).
    void set_predecoded_core(bool on);
    // McuOptions::translate_blocks after construction (not during a run).
    void set_translate_blocks(bool on);
    // Flash bytes [begin, end) were written from outside the firmware (a
    // debugger): the predecoded core decodes them again. SPM needs no call.
    void flash_written(std::uint32_t begin_bytes, std::uint32_t end_bytes);
    // Idle-loop jumps taken and the cycles they covered (mcu/IdleLoopSkip.hpp).
    std::uint64_t idle_jumps() const;
    std::uint64_t idle_cycles_skipped() const;
    // How many times the core went through a reset after power-on.
    unsigned resets() const { return resets_; }
    // Watchdog resets that were no finding: asked for by the firmware
    // (periph/watchdog/WatchdogWatch.hpp) or expected by the board; each with the cycle
    // and the PC the watchdog fired at.
    struct RequestedReset {
        Cycle cycle;
        std::uint32_t pc_bytes;
        bool declared;  // the board expects every reset (not recognised as asked for)
    };
    const std::vector<RequestedReset>& requested_resets() const { return requested_resets_; }
    // One line per such reset, for a run's summary: "watchdog reset asked
    // for by the firmware at 0.036000 s (spinning at 0x00d4 <main+0x2c>)".
    std::vector<std::string> requested_reset_lines() const;
    // A pulse on the RESET pin (an Arduino's auto-reset capacitor when the
    // host opens the port, a reset button): the MCU restarts at its reset
    // vector with MCUSR.EXTRF set (328P §10.2). Between runs only.
    void reset_external();
    // Called after each reset (watchdog, jump to the reset vector), once the
    // I/O registers hold their reset values.
    void on_reset(std::function<void()> fn) { reset_listeners_.push_back(std::move(fn)); }
    // Called when a peripheral takes a pin as an output or lets it go without
    // a DDRx write (a USART's TxDn follows TXEN): Pin::is_output changed.
    // Returns an id for remove_pin_direction_listener (-1: nothing to hear).
    int on_pin_direction_change(std::function<void()> fn);
    void remove_pin_direction_listener(int id);

    // Value of a RAM variable by its ELF symbol (for tests and reports).
    std::uint8_t read_ram_u8(const std::string& symbol) const;
    std::uint16_t read_ram_u16(const std::string& symbol) const;
    // `count` bytes from the RAM symbol on (an array); throws BadInput past RAMEND.
    std::vector<std::uint8_t> read_ram(const std::string& symbol, std::size_t count) const;
    // The data space by address (registers, I/O, SRAM up to RAMEND): a peek
    // and a poke for tests and debuggers; BadInput past RAMEND.
    std::uint8_t peek(std::uint32_t data_address) const;
    void poke(std::uint32_t data_address, std::uint8_t value);
    // All of it, 0..RAMEND (to compare two runs' end states).
    std::vector<std::uint8_t> data_memory() const;
    // simavr's ioctl on this core (AVR_IOCTL_EEPROM_GET, AVR_IOCTL_UART_GET_FLAGS, ...).
    int ioctl(std::uint32_t command, void* data);
    // The lock bits as the boot loader or an SPM left them.
    std::uint8_t lockbits() const;
    // simavr's cycle timers armed now (a fix that forgets to cancel one leaks them).
    std::size_t cycle_timers_armed() const;
    // Whether SLEEP jumps in simulated time (simavr's own callback waits with usleep()).
    bool sleeps_in_virtual_time() const;
    // A simavr I/O module ("adc", "uart" '0', "timer" '1'): for conformance
    // probes on simavr's own IRQs; nullptr if the part has none.
    avr_io_t* io_module(const char* kind, char name = 0) const;

    // The boot section when a boot loader was loaded (McuOptions::bootloader_hex).
    const std::optional<BootSection>& boot() const { return boot_; }
    const std::string& bootloader_path() const { return options_.bootloader_hex; }
    // False once a boot loader has rewritten the application section with
    // something other than the ELF: the ELF's symbols and the oracles taken
    // from it (end of .text, __bad_interrupt, end of .bss) no longer apply.
    bool elf_matches_flash() const { return elf_matches_flash_; }
    // How many times a boot loader handed over to the application (a jump
    // from the boot section to address 0).
    unsigned application_starts() const { return application_starts_; }
    // "function+0x12" from the ELF while the flash holds it; "boot
    // loader+0x4a" in a boot section; else the raw address. For findings.
    std::string describe_pc(std::uint32_t pc_bytes) const;

private:
    friend struct ResetHook;
    void load_bootloader();
    void application_started();
    bool in_boot_section(std::uint32_t pc_bytes) const { return boot_ && pc_bytes >= boot_->start_bytes; }
    bool check_after_step(int state, std::uint32_t pc_before);
    template <bool kCover, bool kProfile, bool kStopAtSleep = false>
    StopReason run_until_impl(Cycle target_cycle, PcEdgeMap* edges);
    void after_reset();
    void add_finding(FindingKind kind, std::uint32_t pc_bytes, std::string detail, bool halt);
    void on_simavr_error(const char* message) override;
    std::uint16_t ram_address_of(const std::string& symbol) const;

    McuOptions options_;
    ElfImage elf_;
    std::string mcu_type_;
    std::uint32_t frequency_hz_ = 0;
    // Declared before the fixes: they find their state in it until they are gone.
    AvrContext context_;
    avr_t* avr_ = nullptr;
    avr_extint_t* extint_ = nullptr;  // simavr's INTn module, for pin_interrupt_enabled
    avr_acomp_t* acomp_ = nullptr;    // simavr's analog comparator
    std::unique_ptr<SimavrFixes> fixes_;
    std::unique_ptr<Scheduler> scheduler_;
    std::unique_ptr<Adc> adc_;
    std::unique_ptr<Twi> twi_;
    std::unique_ptr<IdleLoopSkipper> skipper_;  // nullptr: never skip
    std::unique_ptr<PredecodedCore> predecoded_;  // nullptr: avr_run_one (McuOptions::predecoded_core)
    std::unique_ptr<PredecodedCore> make_predecoded_core() const;
    std::uint32_t skip_countdown_ = 1;
    bool in_run_ = false;
    // simavr's cycle counter and core state (avr_t::cycle, avr_t::state),
    // for the inline getters; cpu_Sleeping is 3 in sim_avr.h (static_assert in Mcu.cpp).
    const std::uint64_t* cycle_ = nullptr;
    const int* state_ = nullptr;
    static constexpr int kCpuSleeping = 3;
    bool no_pending_interrupts() const;
    DebugHook* debug_ = nullptr;
    bool skip_idle_before_debug_ = false;
    bool stop_at_sleep_ = false;  // run_until_sleep: the run loop ends when the core sleeps
    PcEdgeMap* run_coverage_ = nullptr;
    std::unique_ptr<TimingProfiler> profiler_;
    bool real_stop_ = false;  // stop_requested_ came from request_stop, not request_yield
    PeerSync* peer_sync_ = nullptr;
    std::map<std::string, std::unique_ptr<Pin>, std::less<>> pins_;
    std::map<int, std::unique_ptr<Uart>> uarts_;
    std::unique_ptr<Spi> spi_;
    bool spi_looked_for_ = false;
    FindingLog<Finding> findings_;

    // Oracle thresholds, precomputed so the hot loop only compares.
    std::uint32_t code_end_bytes_ = 0;        // first flash byte past .text
    std::uint32_t bad_interrupt_pc_ = ~0u;    // __bad_interrupt, or never
    std::uint16_t stack_floor_ = 0;           // SP below this has overwritten .bss
    std::uint32_t elf_code_end_bytes_ = 0;    // the three above as the ELF gives them
    std::uint32_t elf_bad_interrupt_pc_ = ~0u;
    std::uint16_t elf_stack_floor_ = 0;
    std::optional<BootSection> boot_;
    bool elf_matches_flash_ = true;
    unsigned application_starts_ = 0;

    std::uint64_t steps_ = 0;
    unsigned resets_ = 0;
    std::vector<RequestedReset> requested_resets_;
    std::unique_ptr<WatchdogWatch> watchdog_watch_;
    std::vector<std::function<void()>> reset_listeners_;
    bool stop_requested_ = false;
    bool halted_ = false;
    std::string halt_reason_;
    std::string last_error_log_;
    void (*original_watchdog_reset_)(::avr_io_t*) = nullptr;
    bool watchdog_reset_seen_ = false;
    bool reset_seen_ = false;  // avr_reset ran (inside a step: the watchdog)
};

}  // namespace avrbench
