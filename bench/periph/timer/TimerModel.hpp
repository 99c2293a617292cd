#pragma once

// Timer/Counters 0..5 of the megaAVRs: counting, compare matches, waveform
// generation, input capture and the prescalers, from the datasheets, in place
// of simavr 1.6's avr_timer handlers.
//
// ATmega328P datasheet (DS40002061A): §15 Timer/Counter0, §16 Timer/Counter1,
// §17 prescalers of Timer/Counter0/1, §18 Timer/Counter2; ATmega2560
// (Atmel-2549): §16 Timer/Counter0, §17 Timer/Counter1/3/4/5, §18 their
// prescaler, §20 Timer/Counter2; ATmega32 (Atmel-2503): Timer/Counter0, 1, 2.
//
// What simavr 1.6 gets wrong, and this model does instead (docs/FIDELITY.md
// has the numbers and the tests):
//  - a timer whose period is one cycle (CTC, OCRnA = 0, prescaler 1) never
//    runs: here the compare matches on every timer clock;
//  - TOVn is raised at every CTC period: here only when TCNTn passes MAX;
//  - OCRnA written below TCNTn in CTC fires at once: here the counter runs to
//    MAX and wraps first (§16.9.2);
//  - phase correct and phase and frequency correct PWM count like fast PWM
//    (period TOP+1 instead of 2*TOP) and set/clear OCnx like it; Timer0/2
//    modes 1 and 5 and Timer1 modes 1-3, 8-11 are missing; mode 7 (Timer0/2)
//    and 15 (Timer1) are treated as phase correct;
//  - OCRnx is not double buffered in the PWM modes (§15.7.3: updated at
//    BOTTOM in fast PWM, at TOP in phase correct, §16.9.5: at BOTTOM in phase
//    and frequency correct);
//  - writing TCNTn does not block the compare match of the next timer clock
//    (§16.7.2), and a TCNTn written before the timer first runs is lost;
//  - TCNTn reads are wrong while counting down;
//  - the prescaler is restarted for every timer start instead of running
//    freely and being shared (§17.1, §17.2 "Prescaler Reset"); PSRSYNC,
//    PSRASY, TSM are ignored;
//  - ATmega8/16/32 Timer/Counter2 clk/32 runs at clk/16; ATmega16/32
//    Timer/Counter0 has no CTC or PWM modes; FOCnx strobes do nothing;
//  - an external clock on T1 does not clock Timer1 in CTC mode; the
//    ATmega1280/2560 T1 pin is taken as PD7 (it is PD6);
//  - the input capture noise canceler delay (4 cycles, §16.6.2) is missing;
//  - OCnx rewrites PORTxn (see CompareOutputPins.hpp);
//  - compare-output edges and flags are stamped at the end of the instruction
//    during which the timer clock fell: here listeners see the cycle of the
//    timer clock itself (the rest of the core still runs in instruction steps:
//    an interrupt raised in the middle of an instruction is taken after it).
//
// Conventions (the datasheet leaves them to the implementation):
//  - I/O accesses happen at the cycle the instruction starts (avr->cycle);
//    a read at cycle c sees every timer clock at cycles <= c, a write at c
//    takes effect for timer clocks > c.
//  - A timer clock at cycle t moves TCNTn from v to its next value; the flags
//    and OCnx changes that v causes (v == OCRnx, v == TOP, MAX or BOTTOM) come
//    with that clock: "set in the timer clock cycle after the counter value
//    matches" (§16.11.9 TIFR1), "TOV1 set in the same timer clock cycle as the
//    TCNT1 becomes zero" (§16.9.1). In the dual-slope modes TOVn is set on the
//    clock that leaves BOTTOM, as ICFn/OCFnA are on the one that leaves TOP
//    (§16.10 timing diagrams).
//  - The prescaler starts at reset (and at every PSRSYNC/PSRASY write): with
//    prescaler N, timer clocks fall on cycles reset + k*N.
//
// Cores other than the megaAVRs listed in family_of() keep simavr's timers.
//
// Cost: one simavr cycle timer per timer at the next cycle where something
// happens (a compare match, TOP, BOTTOM, MAX), nothing per instruction. A
// timer whose only effect would be to set again flags that are already set
// (grbl's idle Timer1: CTC at clk/1, OCR1A small, interrupt disabled) stops
// scheduling until a flag is cleared or a register written.
//
// The model lives in three files: TimerCounter.cpp counts (time, timer
// clocks, compare matches, flags, scheduling), TimerReplay.cpp replays a
// steady period and hands periodic waves to the compare outputs, and
// TimerModel.cpp ties it to simavr (configuration, I/O hooks, install).
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

extern "C" {
#include <avr_ioport.h>
#include <avr_timer.h>
#include <sim_cycle_timers.h>
#include <sim_interrupts.h>
#include <sim_io.h>
#include <sim_irq.h>
#include <sim_regbit.h>
}

#include "core/CycleAt.hpp"
#include "periph/timer/CompareOutputPins.hpp"
#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench::timer_model {

using Cycle = avr_cycle_count_t;
__extension__ using Wide = unsigned __int128;  // cycle * (timer clocks per second) products

enum class Wave : std::uint8_t { Normal, Ctc, Fast, PhaseCorrect, PhaseFrequencyCorrect };
enum class TopFrom : std::uint8_t { Fixed, Ocra, Icr };

struct Mode {
    Wave wave = Wave::Normal;
    TopFrom top = TopFrom::Fixed;
    std::uint16_t fixed_top = 0xFF;
    bool com1_toggles_a = false;  // COMnA1:0 = 01 toggles OCnA in this PWM mode

    bool pwm() const { return wave != Wave::Normal && wave != Wave::Ctc; }
    bool dual_slope() const { return wave == Wave::PhaseCorrect || wave == Wave::PhaseFrequencyCorrect; }
};

// Clock Select, CSn2:0 -> prescaler; 0 = stopped, -1 = Tn falling edge,
// -2 = Tn rising edge. ATmega328P Table 15-9/16-5 (Timer0/1 prescaler),
// Table 18-9 (Timer2's own prescaler; the ATmega32's Timer2 has the same).
inline constexpr int kSyncDivisors[8] = {0, 1, 8, 64, 256, 1024, -1, -2};
inline constexpr int kAsyncDivisors[8] = {0, 1, 8, 32, 64, 128, 256, 1024};

// The timer clock source of a prescaler: the system clock or, for Timer2
// with AS2 = 1, the 32.768 kHz crystal on TOSC1/2.
struct Prescaler {
    Cycle base = 0;     // last prescaler reset: timer clocks fall on base + k*period
    bool held = false;  // TSM = 1 with PSRx = 1: the prescaler is kept in reset
};

enum class Family { Modern, Old };

// Where a timer's bits live, beyond what simavr's avr_timer_t describes
// correctly.
struct Shape {
    bool sixteen_bit = false;
    const Mode* modes = nullptr;
    unsigned wgm_bits = 0;
    avr_regbit_t wgm[4] = {};
    const int* divisors = kSyncDivisors;
    bool async_group = false;
    avr_io_addr_t foc_reg = 0;
    std::uint8_t foc_bit[AVR_TIMER_COMP_COUNT] = {};  // bit masks, 0 = none
    avr_regbit_t icnc = {};
    avr_regbit_t ext_pin = {};
};

class TimerModel {
public:
    TimerModel(avr_t* avr, avr_timer_t* timer, const Shape& shape, Prescaler& prescaler, CompareOutputPins& pins);

    ~TimerModel();

    TimerModel(const TimerModel&) = delete;
    TimerModel& operator=(const TimerModel&) = delete;

    // Brings the counter to cycle `now`, running every timer clock up to it.
    // A periodic wave on the compare outputs ends first (at the last period
    // boundary), and the pins are driven edge by edge from there.
    void sync(Cycle now);

    // CompareOutputPins::StopWave: the pin is about to be observed.
    static void stop_wave(void* self, Cycle now) { static_cast<TimerModel*>(self)->sync(now); }

    void sync_counter(Cycle now);

    // The prescaler was reset or released: `sync` ran just before.
    void reschedule();

private:
    // --- time -----------------------------------------------------------------

    bool ticking() const { return clock_divisor_ > 0 && !prescaler_->held; }

    // Timer clock k (k >= 1) after the prescaler base falls on cycle
    // base + floor(k * num / den): num/den cycles per timer clock.
    std::uint64_t tick_index(Cycle c) const;
    Cycle tick_cycle(std::uint64_t k) const;

    // --- counting ---------------------------------------------------------------

    std::uint16_t max_value() const { return shape_.sixteen_bit ? 0xFFFF : 0xFF; }
    std::uint16_t ocr_register(int i) const;
    std::uint16_t icr_register() const;
    std::uint16_t top() const;

    // Timer clocks from now to the next one that does something (>= 1).
    std::uint64_t distance() const;

    // A TCNTn write blocks the compare matches of the next timer clock, and
    // with them the detection of a variable TOP (OCRnA, ICRn): "The Compare
    // Match for the TOP will be ignored and the counter will continue to
    // 0xFFFF" (§16.7.3).
    bool top_blocked(std::uint16_t v, std::uint16_t top_value) const;

    // `n` timer clocks in which nothing happens (n < distance()).
    void advance(std::uint64_t n);

    // The timer clock at cycle t: TCNTn leaves value_.
    void event(Cycle t);

    // What one timer clock does, besides counting: the OCnx levels after it,
    // and the flags it sets (bits 0-2: OCFnA..C, then TOVn, ICFn).
    static constexpr std::uint8_t kRaiseOverflow = 1u << 3;
    static constexpr std::uint8_t kRaiseCapture = 1u << 4;
    struct Outcome {
        bool level[AVR_TIMER_COMP_COUNT] = {};
        std::uint8_t raises = 0;
    };

    // Listeners see cycle t: pins first, then the flags in the order
    // OCFnA, OCFnB, OCFnC, TOVn, ICFn.
    void apply(Cycle t, const Outcome& out);

    // What a compare match does to OCnx (Tables 15-2..15-4, 16-1..16-3).
    void compare_action(int i, int match_dir, bool& level) const;

    bool connected(int i) const;

    // --- scheduling ---------------------------------------------------------------

    void arm();

    Cycle next_event_cycle() const;

    static avr_cycle_count_t on_event(avr_t*, avr_cycle_count_t when, void* param);

    // --- replaying a steady period ---------------------------------------------------
    // A timer whose registers nobody writes repeats the same events every
    // period. After two period starts without a write, one period is run dry
    // (run_period_dry) and from then on each event is taken from that record:
    // the counter's state after it, its pin levels and flags (apply(), as
    // event() does), the distance to the next. Any register write, prescaler
    // reset or reset forgets the record (reschedule(), reset_state()).
    // Exactness: TimerReplay.* (every firmware, with and without).
    void forget_replay();

    // At a period start (at_), from the slow path.
    void maybe_record();

    // One of the flags in `raises` has its interrupt enabled (then the timer
    // cannot be quiescent: maybe_quiesce would find the same).
    bool any_enabled(std::uint8_t raises) const;

    // The event at `when` from the record; false if the record has none there.
    bool replay_event(Cycle when, Cycle& next_out);

    static std::atomic<bool>& replay_enabled();

public:
    static void set_replay_enabled(bool on) { replay_enabled().store(on, std::memory_order_relaxed); }

private:

    // Idle periodic timers whose every effect is already in place: stop
    // scheduling (see the file comment). All of one period's matches, TOVn
    // and ICFn must have their flags set with their interrupts disabled, no
    // OCnx connected, nothing buffered.
    // Timer clocks per period in the present mode (0: none), and whether a
    // period sets TOVn and ICFn.
    std::uint64_t period_clocks(bool& tov, bool& icf) const;

    void maybe_quiesce();

    // --- periodic waves on the compare outputs (periph/timer/PeriodicOutput.hpp) ----------

    // One period's timer events, run on the counter without touching pins or
    // flags: at most one per compare unit per slope, TOP and BOTTOM.
    struct DryEvent {
        Cycle offset = 0;  // cycles after the period's start, 0 < offset <= period
        Outcome out;
        std::uint16_t value = 0;  // TCNTn after it
        std::int8_t dir = 1;
        bool period_start = false;
    };
    struct DryRun {
        static constexpr std::size_t kMaxEvents = 8;
        Cycle start = 0;
        std::size_t count = 0;
        std::array<DryEvent, kMaxEvents> events{};
        bool overflow = false;
        void add(Cycle t, const Outcome& out, std::uint16_t value, std::int8_t dir, bool period_start) {
            if (count == kMaxEvents) {
                overflow = true;
                return;
            }
            events[count++] = {t - start, out, value, dir, period_start};
        }
    };

    // From a period start (at_): one period of `period_cycles`, dry. True if
    // it ends in the state it began (counter, direction, OCnx levels); the
    // model's state is as before either way.
    bool run_period_dry(Cycle period_cycles, DryRun& run);

    // At a period start (at_): hands every connected compare output out as a
    // wave, or none. Needs the prescaler at clk_I/O / 2^k (whole cycles).
    bool begin_waves(std::uint64_t period_clocks);

    // Skips to the last period boundary at or before `now` and ends the waves
    // there. Returns true (for sync's `ended`).
    bool end_waves(Cycle now);

    // Set, and staying set: an enabled vector will soon clear it (and would
    // only wake the model again right away).
    bool flag_set(const avr_int_vector_t& v) const;

    // While quiescent the state repeats every `period_` timer clocks from the anchor.
    void skip_whole_periods(Cycle now);

    // --- configuration ------------------------------------------------------------

    std::vector<avr_int_vector_t*> vectors() const;

    // Mode, clock and compare outputs from the control registers.
    void configure();

    // FOCnx strobes (non-PWM modes only): the compare output action, no flag,
    // no clear of the timer (§15.5.1 / §16.7.1).
    void force(std::uint8_t strobes);

    void reset_state();

    // --- hooks --------------------------------------------------------------------

    static void on_control_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);

    static void on_tcnt_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);

    static std::uint8_t on_tcnt_read(IoReadHook& hook, avr_t* avr, avr_io_addr_t);

    static void on_ocr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);

    static void on_icr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value);

    // Input capture (§16.6): ICRn <- TCNTn on the edge ICESn selects, ICFn set;
    // with ICNCn the edge counts after four equal samples, four cycles later.
    static void on_icp_pin(avr_irq_t*, std::uint32_t value, void* param);

    static avr_cycle_count_t on_noise_canceler(avr_t*, avr_cycle_count_t when, void* param);

    void capture_edge(bool level, Cycle at);

    // External clock on Tn (CSn2:0 = 110 falling, 111 rising): one timer clock
    // per edge, at the cycle of the edge (silicon: 2.5..3.5 cycles later, §17.3).
    static void on_ext_pin(avr_irq_t* irq, std::uint32_t value, void* param);

    // A flag was cleared (TIFRn write, or the vector was taken): a quiescent
    // timer must set it again at the next match.
    static void on_flag_change(avr_irq_t*, std::uint32_t value, void* param);

    static void on_io_reset(avr_io_t* io);

    avr_t* avr_;
    avr_timer_t* t_;
    Shape shape_;
    Prescaler* prescaler_;
    CompareOutputPins* pins_;
    std::vector<std::unique_ptr<IoWriteHook>> hooks_;
    std::unique_ptr<IoReadHook> tcnt_read_;
    avr_irq_t* icp_irq_ = nullptr;
    avr_irq_t* ext_irq_ = nullptr;
    void (*original_reset_)(avr_io_t*) = nullptr;

    Mode mode_;
    std::uint32_t clock_divisor_ = 0;  // 0: stopped or external
    std::uint64_t num_ = 1, den_ = 1;  // cycles per timer clock = num_ / den_
    unsigned shift_ = 0;               // log2(num_) while den_ == 1
    int ext_edge_ = 0;                 // 1: Tn falling, 2: Tn rising

    std::uint16_t value_ = 0;  // TCNTn at cycle at_
    std::int8_t dir_ = 1;
    Cycle at_ = 0;
    bool block_compare_ = false;
    bool has_comp_[AVR_TIMER_COMP_COUNT] = {};
    std::uint16_t ocr_[AVR_TIMER_COMP_COUNT] = {};  // compare values in use (OCRnx behind the buffer)
    bool oc_[AVR_TIMER_COMP_COUNT] = {};            // the OCnx registers
    std::uint8_t com_[AVR_TIMER_COMP_COUNT] = {};   // COMnx1:0, as of the last control write
    int driver_[AVR_TIMER_COMP_COUNT] = {-1, -1, -1};

    bool icp_level_ = false;  // after the noise canceler
    bool icnc_pending_level_ = false;

    Cycle next_cache_ = 0;       // the next event's cycle, as sync() last found it
    bool next_valid_ = false;
    bool in_event_ = false;      // inside on_event: arm() leaves the cycle timer to it
    bool rearmed_ = false;
    bool period_start_ = false;  // the last event wrapped (or turned at TOP)
    bool quiescent_ = false;
    bool waving_ = false;          // quiescent with the compare outputs handed out as waves
    struct Replay {
        bool valid = false;
        bool tried = false;     // recorded or failed since the last register write
        Cycle anchor = 0;       // a period start
        Cycle period = 0;       // cycles (two timer periods when an output toggles)
        DryRun run;
        std::size_t next_index = 0;  // the event the cycle timer is armed for
        Cycle next_cycle = 0;
        std::uint8_t raises = 0;     // every flag the period sets
    };
    Replay replay_;
    unsigned steady_periods_ = 0;  // period starts since a register was last written
    DryRun* dry_run_ = nullptr;    // inside begin_waves: event() records instead of acting
    std::uint64_t period_ = 1;
    Cycle anchor_at_ = 0;
    std::uint16_t anchor_value_ = 0;
    std::int8_t anchor_dir_ = 1;
};

}  // namespace avrbench::timer_model
