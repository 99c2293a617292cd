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
#include <array>
#include <atomic>
#include <map>
#include <mutex>
#include <string_view>
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

namespace avrbench {
namespace {

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

constexpr Mode kNormal8{Wave::Normal, TopFrom::Fixed, 0xFF, false};
constexpr Mode kNormal16{Wave::Normal, TopFrom::Fixed, 0xFFFF, false};

// ATmega328P Table 15-8 (Timer0) and Table 18-8 (Timer2), WGMn2:0; reserved
// modes 4 and 6 run as Normal.
constexpr Mode kModes8[8] = {
    kNormal8,
    {Wave::PhaseCorrect, TopFrom::Fixed, 0xFF, false},
    {Wave::Ctc, TopFrom::Ocra, 0, false},
    {Wave::Fast, TopFrom::Fixed, 0xFF, false},
    kNormal8,
    {Wave::PhaseCorrect, TopFrom::Ocra, 0, true},
    kNormal8,
    {Wave::Fast, TopFrom::Ocra, 0, true},
};

// ATmega32 Timer/Counter0 and 2 (TCCR0/TCCR2: WGMn1:0 in bits 3 and 6);
// COMn1:0 = 01 is reserved in both PWM modes.
constexpr Mode kModes8TwoBits[4] = {
    kNormal8,
    {Wave::PhaseCorrect, TopFrom::Fixed, 0xFF, false},
    {Wave::Ctc, TopFrom::Ocra, 0, false},
    {Wave::Fast, TopFrom::Fixed, 0xFF, false},
};

// ATmega328P Table 16-4 (Timer1, WGM13:0; same on the 2560's Timer1/3/4/5 and
// the ATmega32's Timer1). Mode 13 is reserved: runs as Normal. COM1A = 01
// toggles OC1A in modes 14, 15 (Table 16-2) and 9, 11 (Table 16-3).
constexpr Mode kModes16[16] = {
    kNormal16,
    {Wave::PhaseCorrect, TopFrom::Fixed, 0x00FF, false},
    {Wave::PhaseCorrect, TopFrom::Fixed, 0x01FF, false},
    {Wave::PhaseCorrect, TopFrom::Fixed, 0x03FF, false},
    {Wave::Ctc, TopFrom::Ocra, 0, false},
    {Wave::Fast, TopFrom::Fixed, 0x00FF, false},
    {Wave::Fast, TopFrom::Fixed, 0x01FF, false},
    {Wave::Fast, TopFrom::Fixed, 0x03FF, false},
    {Wave::PhaseFrequencyCorrect, TopFrom::Icr, 0, false},
    {Wave::PhaseFrequencyCorrect, TopFrom::Ocra, 0, true},
    {Wave::PhaseCorrect, TopFrom::Icr, 0, false},
    {Wave::PhaseCorrect, TopFrom::Ocra, 0, true},
    {Wave::Ctc, TopFrom::Icr, 0, false},
    kNormal16,
    {Wave::Fast, TopFrom::Icr, 0, true},
    {Wave::Fast, TopFrom::Ocra, 0, true},
};

// Clock Select, CSn2:0 -> prescaler; 0 = stopped, -1 = Tn falling edge,
// -2 = Tn rising edge. ATmega328P Table 15-9/16-5 (Timer0/1 prescaler),
// Table 18-9 (Timer2's own prescaler; the ATmega32's Timer2 has the same).
constexpr int kSyncDivisors[8] = {0, 1, 8, 64, 256, 1024, -1, -2};
constexpr int kAsyncDivisors[8] = {0, 1, 8, 32, 64, 128, 256, 1024};

// The timer clock source of a prescaler: the system clock or, for Timer2
// with AS2 = 1, the 32.768 kHz crystal on TOSC1/2.
struct Prescaler {
    Cycle base = 0;     // last prescaler reset: timer clocks fall on base + k*period
    bool held = false;  // TSM = 1 with PSRx = 1: the prescaler is kept in reset
};

enum class Family { Modern, Old };

// The timers the model knows: the ATmega48/88/168/328, 164/324/644/1284,
// 1280/1281/2560 (GTCCR, TCCRnA/B/C) and the ATmega8/16/32 (SFIOR, TCCR0/2).
bool family_of(std::string_view mmcu, Family& family) {
    for (std::string_view m : {"atmega8", "atmega16", "atmega32"}) {
        if (mmcu == m) {
            family = Family::Old;
            return true;
        }
    }
    for (std::string_view m : {"atmega48", "atmega88", "atmega168", "atmega328", "atmega164", "atmega324",
                               "atmega324a", "atmega644", "atmega1284", "atmega1280", "atmega1281", "atmega2560"}) {
        if (mmcu == m) {
            family = Family::Modern;
            return true;
        }
    }
    return false;
}

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

avr_regbit_t regbit(avr_io_addr_t reg, unsigned bit) {
    avr_regbit_t rb{};
    rb.reg = reg & 0x1FF;
    rb.bit = bit & 7;
    rb.mask = 1;
    return rb;
}

Shape shape_of(const avr_t* avr, const avr_timer_t* t, Family family) {
    Shape s;
    s.sixteen_bit = t->r_tcnth != 0;
    s.ext_pin = t->ext_clock_pin;
    if (s.sixteen_bit) {
        s.modes = kModes16;
        s.wgm_bits = 4;
        for (int i = 0; i < 4; ++i) s.wgm[i] = t->wgm[i];
        const avr_io_addr_t tccrb = t->cs[0].reg;
        s.icnc = regbit(tccrb, 7);  // ICNCn: TCCRnB bit 7
        if (family == Family::Modern) {
            s.foc_reg = static_cast<avr_io_addr_t>(tccrb + 1);  // TCCRnC: FOCnA/B/C in bits 7/6/5
            s.foc_bit[0] = 0x80;
            s.foc_bit[1] = 0x40;
            s.foc_bit[2] = 0x20;
        } else {
            s.foc_reg = t->comp[0].com.reg;  // ATmega32 TCCR1A: FOC1A bit 3, FOC1B bit 2
            s.foc_bit[0] = 0x08;
            s.foc_bit[1] = 0x04;
        }
        // ATmega2560/1280: T1 is PD6 (§1 "Pin Configurations", Table 13-9 "Port D"); simavr has PD7 (T0).
        const std::string_view mmcu = avr->mmcu;
        if (t->name == '1' && (mmcu == "atmega2560" || mmcu == "atmega1280")) s.ext_pin.bit = 6;
        return s;
    }
    s.async_group = t->as2.reg != 0;
    s.divisors = s.async_group ? kAsyncDivisors : kSyncDivisors;
    if (t->wgm[2].reg != 0) {
        s.modes = kModes8;
        s.wgm_bits = 3;
        for (int i = 0; i < 3; ++i) s.wgm[i] = t->wgm[i];
    } else if (t->wgm[0].reg != 0) {
        s.modes = kModes8TwoBits;
        s.wgm_bits = 2;
        for (int i = 0; i < 2; ++i) s.wgm[i] = t->wgm[i];
    } else if (t->comp[0].r_ocr != 0 && t->comp[0].com.reg != 0) {
        // ATmega16/32 Timer/Counter0: TCCR0 holds WGM00 (bit 6) and WGM01
        // (bit 3); simavr declares neither.
        s.modes = kModes8TwoBits;
        s.wgm_bits = 2;
        s.wgm[0] = regbit(t->comp[0].com.reg, 6);
        s.wgm[1] = regbit(t->comp[0].com.reg, 3);
    } else {
        s.modes = kModes8;  // ATmega8 Timer/Counter0: Normal mode only
        s.wgm_bits = 0;
    }
    const avr_io_addr_t tccrb = t->cs[0].reg;  // TCCRnB (modern) or TCCRn (old)
    s.foc_reg = tccrb;
    if (family == Family::Modern) {
        s.foc_bit[0] = 0x80;  // FOCnA
        s.foc_bit[1] = 0x40;  // FOCnB
    } else if (s.wgm_bits != 0) {
        s.foc_bit[0] = 0x80;  // FOC0 / FOC2
    } else {
        s.foc_reg = 0;
    }
    return s;
}

avr_irq_t* pin_irq(avr_t* avr, avr_regbit_t pin) {
    if (pin.reg == 0) return nullptr;
    avr_ioport_getirq_t req{};
    req.bit = pin;
    if (avr_ioctl(avr, AVR_IOCTL_IOPORT_GETIRQ_REGBIT, &req) > 0) return req.irq[0];
    return nullptr;
}


class TimerModel {
public:
    TimerModel(avr_t* avr, avr_timer_t* timer, const Shape& shape, Prescaler& prescaler, CompareOutputPins& pins)
        : avr_(avr), t_(timer), shape_(shape), prescaler_(&prescaler), pins_(&pins) {
        mode_ = shape_.modes[0];
        at_ = avr->cycle;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            has_comp_[i] = t_->comp[i].r_ocr != 0;
            driver_[i] = has_comp_[i] ? pins_->add(t_->comp[i].com_pin, t_->io.irq + TIMER_IRQ_OUT_COMP + i) : -1;
        }

        std::vector<avr_io_addr_t> control;
        auto add_control = [&](avr_io_addr_t reg) {
            if (reg == 0) return;
            for (avr_io_addr_t r : control) {
                if (r == reg) return;
            }
            control.push_back(reg);
        };
        for (unsigned i = 0; i < shape_.wgm_bits; ++i) add_control(shape_.wgm[i].reg);
        for (const auto& cs : t_->cs) add_control(cs.reg);
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) add_control(t_->comp[i].com.reg);
        add_control(t_->as2.reg);
        add_control(shape_.foc_reg);
        add_control(t_->ices.reg);
        for (avr_io_addr_t reg : control) hooks_.push_back(std::make_unique<IoWriteHook>(avr, reg, &on_control_write, this));
        hooks_.push_back(std::make_unique<IoWriteHook>(avr, t_->r_tcnt, &on_tcnt_write, this));
        tcnt_read_ = std::make_unique<IoReadHook>(avr, t_->r_tcnt, &on_tcnt_read, this);
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (has_comp_[i]) {
                hooks_.push_back(std::make_unique<IoWriteHook>(avr, t_->comp[i].r_ocr, &on_ocr_write, this));
            }
        }
        if (t_->r_icr != 0) hooks_.push_back(std::make_unique<IoWriteHook>(avr, t_->r_icr, &on_icr_write, this));

        icp_irq_ = pin_irq(avr, t_->icp);
        if (icp_irq_ != nullptr) {
            avr_unconnect_irq(icp_irq_, t_->io.irq + TIMER_IRQ_IN_ICP);
            avr_irq_register_notify(icp_irq_, &on_icp_pin, this);
            icp_level_ = (icp_irq_->value & 0xFF) != 0;
        }
        ext_irq_ = pin_irq(avr, shape_.ext_pin);
        if (ext_irq_ != nullptr) avr_irq_register_notify(ext_irq_, &on_ext_pin, this);
        for (avr_int_vector_t* v : vectors()) avr_irq_register_notify(v->irq + AVR_INT_IRQ_PENDING, &on_flag_change, this);

        original_reset_ = t_->io.reset;
        t_->io.reset = &on_io_reset;
        // simavr's io reset callback has no parameter.
        FixState<TimerModel>::add(&t_->io, this);
    }

    ~TimerModel() {
        FixState<TimerModel>::remove(&t_->io);
        t_->io.reset = original_reset_;
        avr_cycle_timer_cancel(avr_, &on_event, this);
        avr_cycle_timer_cancel(avr_, &on_noise_canceler, this);
        if (icp_irq_ != nullptr) avr_irq_unregister_notify(icp_irq_, &on_icp_pin, this);
        if (ext_irq_ != nullptr) avr_irq_unregister_notify(ext_irq_, &on_ext_pin, this);
        for (avr_int_vector_t* v : vectors()) avr_irq_unregister_notify(v->irq + AVR_INT_IRQ_PENDING, &on_flag_change, this);
    }

    TimerModel(const TimerModel&) = delete;
    TimerModel& operator=(const TimerModel&) = delete;

    // Brings the counter to cycle `now`, running every timer clock up to it.
    // A periodic wave on the compare outputs ends first (at the last period
    // boundary), and the pins are driven edge by edge from there.
    void sync(Cycle now) {
        const bool ended = waving_ && end_waves(now);
        sync_counter(now);
        if (ended) arm();
    }

    // CompareOutputPins::StopWave: the pin is about to be observed.
    static void stop_wave(void* self, Cycle now) { static_cast<TimerModel*>(self)->sync(now); }

    void sync_counter(Cycle now) {
        if (now <= at_) return;
        if (!ticking()) {
            at_ = now;
            return;
        }
        if (quiescent_) skip_whole_periods(now);
        for (;;) {
            const Cycle t = next_valid_ ? next_cache_ : tick_cycle(tick_index(at_) + distance());
            if (t > now) {
                advance(tick_index(now) - tick_index(at_));
                at_ = now;
                next_cache_ = t;  // advancing inside the quiet stretch keeps it
                next_valid_ = true;
                return;
            }
            advance(tick_index(t) - tick_index(at_) - 1);
            event(t);
        }
    }

    // The prescaler was reset or released: `sync` ran just before.
    void reschedule() {
        quiescent_ = false;
        next_valid_ = false;
        forget_replay();
        arm();
    }

private:
    // --- time -----------------------------------------------------------------

    bool ticking() const { return clock_divisor_ > 0 && !prescaler_->held; }

    // Timer clock k (k >= 1) after the prescaler base falls on cycle
    // base + floor(k * num / den): num/den cycles per timer clock.
    std::uint64_t tick_index(Cycle c) const {
        const Cycle base = prescaler_->base;
        if (c < base) return 0;
        if (den_ == 1) return (c - base) >> shift_;  // clk_I/O / N, N a power of two
        const Wide x = static_cast<Wide>(c - base + 1) * den_ - 1;
        return static_cast<std::uint64_t>(x / num_);
    }
    Cycle tick_cycle(std::uint64_t k) const {
        if (den_ == 1) return prescaler_->base + (k << shift_);
        return prescaler_->base + static_cast<Cycle>(static_cast<Wide>(k) * num_ / den_);
    }

    // --- counting ---------------------------------------------------------------

    std::uint16_t max_value() const { return shape_.sixteen_bit ? 0xFFFF : 0xFF; }
    std::uint16_t ocr_register(int i) const {
        const auto& c = t_->comp[i];
        return static_cast<std::uint16_t>(avr_->data[c.r_ocr] | (c.r_ocrh != 0 ? avr_->data[c.r_ocrh] << 8 : 0));
    }
    std::uint16_t icr_register() const {
        return static_cast<std::uint16_t>(avr_->data[t_->r_icr] | (t_->r_icrh != 0 ? avr_->data[t_->r_icrh] << 8 : 0));
    }
    std::uint16_t top() const {
        switch (mode_.top) {
            case TopFrom::Ocra:
                return ocr_[0];
            case TopFrom::Icr:
                return t_->r_icr != 0 ? icr_register() : max_value();
            case TopFrom::Fixed:
                break;
        }
        return mode_.fixed_top;
    }

    // Timer clocks from now to the next one that does something (>= 1).
    std::uint64_t distance() const {
        const std::uint16_t v = value_;
        const std::uint16_t top_value = top();
        const std::uint16_t end =
            (mode_.wave == Wave::Normal || v > top_value || top_blocked(v, top_value)) ? max_value() : top_value;
        std::uint64_t best;
        if (mode_.dual_slope() && dir_ < 0) {
            best = static_cast<std::uint64_t>(v) + 1;  // leaving BOTTOM
        } else {
            best = static_cast<std::uint64_t>(end - v) + 1;
            if (mode_.dual_slope() && v == 0) best = 1;  // leaving BOTTOM
        }
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (!has_comp_[i]) continue;
            const std::uint16_t o = ocr_[i];
            std::uint64_t d;
            if (dir_ > 0) {
                if (o < v) continue;
                d = static_cast<std::uint64_t>(o - v) + 1;
            } else {
                if (o > v) continue;
                d = static_cast<std::uint64_t>(v - o) + 1;
            }
            if (d == 1 && block_compare_) continue;
            if (d < best) best = d;
        }
        return best;
    }

    // A TCNTn write blocks the compare matches of the next timer clock, and
    // with them the detection of a variable TOP (OCRnA, ICRn): "The Compare
    // Match for the TOP will be ignored and the counter will continue to
    // 0xFFFF" (§16.7.3).
    bool top_blocked(std::uint16_t v, std::uint16_t top_value) const {
        return block_compare_ && mode_.top != TopFrom::Fixed && v == top_value;
    }

    // `n` timer clocks in which nothing happens (n < distance()).
    void advance(std::uint64_t n) {
        if (n == 0) return;
        value_ = static_cast<std::uint16_t>(dir_ > 0 ? value_ + n : value_ - n);
        block_compare_ = false;
    }

    // The timer clock at cycle t: TCNTn leaves value_.
    void event(Cycle t) {
        next_valid_ = false;
        const std::uint16_t v = value_;
        const std::uint16_t mx = max_value();
        // A blocked variable TOP is not TOP: the counter goes on to MAX.
        const std::uint16_t top_value = top_blocked(v, top()) ? mx : top();
        bool tov = false, icf = false, at_bottom_fast = false, update = false;
        int match_dir = dir_;
        std::uint16_t next = static_cast<std::uint16_t>(v + 1);
        int next_dir = dir_;
        period_start_ = false;
        switch (mode_.wave) {
            case Wave::Normal:
                if (v == mx) {
                    next = 0;
                    tov = true;
                    period_start_ = true;
                }
                break;
            case Wave::Ctc:
                if (v == top_value) {
                    next = 0;
                    icf = mode_.top == TopFrom::Icr;
                    period_start_ = true;
                } else if (v == mx) {
                    next = 0;
                }
                tov = v == mx;  // §16.9.2: TOV1 "set in the same timer clock cycle that the counter counts from MAX to 0x0000"
                break;
            case Wave::Fast:
                if (v == top_value || v == mx) {
                    next = 0;
                    at_bottom_fast = true;
                    update = true;  // OCRnx updated at BOTTOM
                    if (v == top_value) {
                        tov = true;  // TOVn set at TOP
                        icf = mode_.top == TopFrom::Icr;
                        period_start_ = true;
                    }
                }
                break;
            case Wave::PhaseCorrect:
            case Wave::PhaseFrequencyCorrect: {
                const bool pfc = mode_.wave == Wave::PhaseFrequencyCorrect;
                if (dir_ > 0 && v == top_value) {
                    // Leaving TOP: count down; OCFnA/ICFn (when TOP) set with the
                    // OCRnx update of phase correct mode (§16.9.4).
                    next = top_value > 0 ? static_cast<std::uint16_t>(top_value - 1) : 0;
                    next_dir = top_value > 0 ? -1 : 1;
                    match_dir = -1;  // OCR = TOP acts as a down-counting match (§15.7.4)
                    icf = mode_.top == TopFrom::Icr;
                    update = !pfc;
                    tov = v == 0;
                    period_start_ = top_value > 0;
                } else if (v == 0) {
                    // Leaving BOTTOM: count up; TOVn set (§16.9.4, §16.9.5).
                    next = 1;
                    next_dir = 1;
                    match_dir = 1;
                    tov = true;
                    update = pfc;
                } else if (dir_ > 0) {
                    next = v == mx ? 0 : static_cast<std::uint16_t>(v + 1);  // above TOP: on to MAX and wrap (assumed)
                } else {
                    next = static_cast<std::uint16_t>(v - 1);
                }
                break;
            }
        }

        bool matched[AVR_TIMER_COMP_COUNT] = {};
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            matched[i] = has_comp_[i] && !block_compare_ && ocr_[i] == v;
        }
        value_ = next;
        dir_ = static_cast<std::int8_t>(next_dir);
        at_ = t;
        block_compare_ = false;

        bool level[AVR_TIMER_COMP_COUNT];
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            level[i] = oc_[i];
            if (com_[i] == 0) continue;  // COMnx = 00: no action on OCnx
            if (matched[i]) compare_action(i, match_dir, level[i]);
            if (at_bottom_fast && has_comp_[i]) {
                // Fast PWM: COMnx = 10 sets, 11 clears OCnx at BOTTOM (Tables 15-3,
                // 16-2); with OCRnx = TOP this wins over the match (their note 1).
                const std::uint8_t com = com_[i];
                if (com == 2) level[i] = true;
                if (com == 3) level[i] = false;
            }
        }
        if (update) {
            for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
                if (has_comp_[i]) ocr_[i] = ocr_register(i);
            }
        }

        Outcome out;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            out.level[i] = level[i];
            if (matched[i]) out.raises = static_cast<std::uint8_t>(out.raises | (1u << i));
        }
        if (tov) out.raises = static_cast<std::uint8_t>(out.raises | kRaiseOverflow);
        if (icf) out.raises = static_cast<std::uint8_t>(out.raises | kRaiseCapture);
        if (dry_run_ != nullptr) {
            for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) oc_[i] = level[i];
            dry_run_->add(t, out, value_, dir_, period_start_);
            return;
        }
        apply(t, out);
    }

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
    void apply(Cycle t, const Outcome& out) {
        CycleAt stamp(avr_, t);
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (out.level[i] != oc_[i]) {
                oc_[i] = out.level[i];
                pins_->set(driver_[i], connected(i), oc_[i]);
            }
        }
        if (out.raises == 0) return;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if ((out.raises >> i) & 1) avr_raise_interrupt(avr_, &t_->comp[i].interrupt);
        }
        if ((out.raises & kRaiseOverflow) != 0) avr_raise_interrupt(avr_, &t_->overflow);
        if ((out.raises & kRaiseCapture) != 0) avr_raise_interrupt(avr_, &t_->icr);
    }

    // What a compare match does to OCnx (Tables 15-2..15-4, 16-1..16-3).
    void compare_action(int i, int match_dir, bool& level) const {
        const std::uint8_t com = com_[i];
        if (com == 0) return;
        if (com == 1) {
            if (!mode_.pwm() || (i == 0 && mode_.com1_toggles_a)) level = !level;
            return;
        }
        if (!mode_.pwm() || mode_.wave == Wave::Fast) {
            level = com == 3;  // non-PWM: 10 clear, 11 set; fast PWM: the same on the match
            return;
        }
        const bool up = match_dir > 0;  // dual slope: 10 clears up, sets down; 11 the reverse
        level = (com == 3) == up;
    }

    bool connected(int i) const {
        const std::uint8_t com = com_[i];
        if (com == 0) return false;
        if (com == 1 && mode_.pwm() && !(i == 0 && mode_.com1_toggles_a)) return false;  // "reserved"/disconnected
        return true;
    }

    // --- scheduling ---------------------------------------------------------------

    void arm() {
        if (in_event_) {
            rearmed_ = true;  // on_event returns the next cycle itself
            return;
        }
        avr_cycle_timer_cancel(avr_, &on_event, this);
        const Cycle next = next_event_cycle();
        if (next == 0) return;
        avr_cycle_timer_register(avr_, next > avr_->cycle ? next - avr_->cycle : 0, &on_event, this);
    }

    Cycle next_event_cycle() const {
        if (!ticking() || quiescent_) return 0;
        if (next_valid_) return next_cache_;
        return tick_cycle(tick_index(at_) + distance());
    }

    static avr_cycle_count_t on_event(avr_t*, avr_cycle_count_t when, void* param) {
        auto* self = static_cast<TimerModel*>(param);
        Cycle next_replayed = 0;
        if (self->replay_.valid && !self->quiescent_ && self->at_ < when && self->replay_event(when, next_replayed)) {
            return next_replayed;
        }
        self->in_event_ = true;
        self->rearmed_ = false;
        self->sync(when);
        self->in_event_ = false;
        // A listener that wrote a timer register has synced the model past
        // `when` (arm() left the cycle timer to us): no period start to check.
        if (!self->rearmed_ && self->period_start_ && self->at_ == when) {
            self->maybe_quiesce();
            if (!self->quiescent_) self->maybe_record();
        }
        const Cycle next = self->next_event_cycle();
        return next > when ? next : 0;
    }

    // --- replaying a steady period ---------------------------------------------------
    // A timer whose registers nobody writes repeats the same events every
    // period. After two period starts without a write, one period is run dry
    // (run_period_dry) and from then on each event is taken from that record:
    // the counter's state after it, its pin levels and flags (apply(), as
    // event() does), the distance to the next. Any register write, prescaler
    // reset or reset forgets the record (reschedule(), reset_state()).
    // Exactness: TimerReplay.* (every firmware, with and without).
    void forget_replay() {
        replay_.valid = false;
        replay_.tried = false;
        steady_periods_ = 0;
    }

    // At a period start (at_), from the slow path.
    void maybe_record() {
        if (replay_.valid || replay_.tried || !replay_enabled().load(std::memory_order_relaxed) || !ticking() ||
            den_ != 1) {
            return;
        }
        if (++steady_periods_ < 2) return;
        replay_.tried = true;  // once per configuration
        bool tov = false, icf = false;
        const std::uint64_t period = period_clocks(tov, icf);
        if (period == 0) return;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (has_comp_[i] && ocr_[i] != ocr_register(i)) return;
        }
        // A compare output that toggles comes back after two periods.
        Cycle cycles = static_cast<Cycle>(period) << shift_;
        if (!run_period_dry(cycles, replay_.run)) {
            cycles *= 2;
            if (!run_period_dry(cycles, replay_.run)) return;
        }
        if (replay_.run.count == 0) return;
        replay_.valid = true;
        replay_.anchor = at_;
        replay_.period = cycles;
        replay_.next_index = 0;
        replay_.next_cycle = at_ + replay_.run.events[0].offset;
        replay_.raises = 0;
        for (std::size_t k = 0; k < replay_.run.count; ++k) {
            replay_.raises = static_cast<std::uint8_t>(replay_.raises | replay_.run.events[k].out.raises);
        }
    }

    // One of the flags in `raises` has its interrupt enabled (then the timer
    // cannot be quiescent: maybe_quiesce would find the same).
    bool any_enabled(std::uint8_t raises) const {
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (((raises >> i) & 1) && avr_regbit_get(avr_, t_->comp[i].interrupt.enable) != 0) return true;
        }
        if ((raises & kRaiseOverflow) != 0 && avr_regbit_get(avr_, t_->overflow.enable) != 0) return true;
        return (raises & kRaiseCapture) != 0 && avr_regbit_get(avr_, t_->icr.enable) != 0;
    }

    // The event at `when` from the record; false if the record has none there.
    bool replay_event(Cycle when, Cycle& next_out) {
        const DryRun& run = replay_.run;
        std::size_t k = replay_.next_index;
        if (when != replay_.next_cycle) {
            // The previous event ran on the slow path (a sync caught up with it).
            const Cycle into = (when - replay_.anchor) % replay_.period;
            const Cycle offset = into == 0 ? replay_.period : into;
            k = 0;
            while (k < run.count && run.events[k].offset != offset) ++k;
            if (k == run.count) return false;
        }
        const DryEvent& e = run.events[k];
        in_event_ = true;
        rearmed_ = false;
        value_ = e.value;
        dir_ = e.dir;
        at_ = when;
        block_compare_ = false;
        period_start_ = e.period_start;
        next_cache_ = k + 1 < run.count ? when + (run.events[k + 1].offset - e.offset)
                                        : when + (replay_.period - e.offset) + run.events[0].offset;
        next_valid_ = true;
        replay_.next_index = k + 1 < run.count ? k + 1 : 0;
        replay_.next_cycle = next_cache_;
        apply(when, e.out);
        in_event_ = false;
        if (!rearmed_ && period_start_ && at_ == when && !any_enabled(replay_.raises)) maybe_quiesce();
        const Cycle next = next_event_cycle();
        next_out = next > when ? next : 0;
        return true;
    }

    static std::atomic<bool>& replay_enabled() {
        static std::atomic<bool> on{true};
        return on;
    }

public:
    static void set_replay_enabled(bool on) { replay_enabled().store(on, std::memory_order_relaxed); }

private:

    // Idle periodic timers whose every effect is already in place: stop
    // scheduling (see the file comment). All of one period's matches, TOVn
    // and ICFn must have their flags set with their interrupts disabled, no
    // OCnx connected, nothing buffered.
    // Timer clocks per period in the present mode (0: none), and whether a
    // period sets TOVn and ICFn.
    std::uint64_t period_clocks(bool& tov, bool& icf) const {
        const std::uint16_t top_value = top();
        tov = true;
        icf = false;
        switch (mode_.wave) {
            case Wave::Normal:
                return static_cast<std::uint64_t>(max_value()) + 1;
            case Wave::Ctc:
                tov = top_value == max_value();
                icf = mode_.top == TopFrom::Icr;
                return static_cast<std::uint64_t>(top_value) + 1;
            case Wave::Fast:
                icf = mode_.top == TopFrom::Icr;
                return static_cast<std::uint64_t>(top_value) + 1;
            case Wave::PhaseCorrect:
            case Wave::PhaseFrequencyCorrect:
                icf = mode_.top == TopFrom::Icr;
                return 2ull * top_value;
        }
        return 0;
    }

    void maybe_quiesce() {
        if (!ticking() || block_compare_) return;
        const std::uint16_t top_value = top();
        bool tov = true, icf = false;
        const std::uint64_t period = period_clocks(tov, icf);
        if (period == 0) return;
        if (tov && !flag_set(t_->overflow)) return;
        if (icf && !flag_set(t_->icr)) return;
        bool outputs = false;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (!has_comp_[i]) continue;
            if (com_[i] != 0) {
                if (!connected(i) || driver_[i] < 0) return;
                outputs = true;
            }
            if (ocr_[i] != ocr_register(i)) return;
            const bool matches = mode_.wave == Wave::Normal || ocr_[i] <= top_value;
            if (matches && !flag_set(t_->comp[i].interrupt)) return;
        }
        if (outputs && !begin_waves(period)) return;
        quiescent_ = true;
        period_ = period;
        anchor_at_ = at_;
        anchor_value_ = value_;
        anchor_dir_ = dir_;
    }

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
    bool run_period_dry(Cycle period_cycles, DryRun& run) {
        if (den_ != 1 || block_compare_) return false;
        run.start = at_;
        run.count = 0;
        run.overflow = false;
        const std::uint16_t value = value_;
        const std::int8_t dir = dir_;
        const Cycle at = at_;
        bool oc[AVR_TIMER_COMP_COUNT];
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) oc[i] = oc_[i];
        dry_run_ = &run;
        const Cycle end = at_ + period_cycles;
        while (at_ < end) {
            const Cycle t = tick_cycle(tick_index(at_) + distance());
            if (t > end) break;
            advance(tick_index(t) - tick_index(at_) - 1);
            event(t);
        }
        dry_run_ = nullptr;
        bool periodic = at_ == end && value_ == value && dir_ == dir && !run.overflow && !block_compare_;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            periodic = periodic && oc_[i] == oc[i];
            oc_[i] = oc[i];
        }
        value_ = value;
        dir_ = dir;
        at_ = at;
        next_valid_ = false;
        period_start_ = true;
        block_compare_ = false;
        return periodic;
    }

    // At a period start (at_): hands every connected compare output out as a
    // wave, or none. Needs the prescaler at clk_I/O / 2^k (whole cycles).
    bool begin_waves(std::uint64_t period_clocks) {
        const Cycle period_cycles = static_cast<Cycle>(period_clocks) << shift_;
        DryRun run;
        if (!run_period_dry(period_cycles, run)) return false;
        PeriodicWave waves[AVR_TIMER_COMP_COUNT];
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            PeriodicWave& w = waves[i];
            w.start = at_;
            w.period = period_cycles;
            w.start_level = oc_[i];
            bool level = oc_[i];
            for (std::size_t k = 0; k < run.count; ++k) {
                if (run.events[k].out.level[i] == level) continue;
                level = run.events[k].out.level[i];
                if (w.edge_count == PeriodicWave::kMaxEdges) return false;
                w.edges[w.edge_count++] = {run.events[k].offset, level};
            }
        }
        CycleAt stamp(avr_, at_);  // sinks see the wave's start, not the end of the instruction
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (!has_comp_[i] || com_[i] == 0) continue;
            if (pins_->begin_wave(driver_[i], waves[i], &stop_wave, this)) continue;
            for (int j = 0; j < i; ++j) {
                if (has_comp_[j] && com_[j] != 0) pins_->end_wave(driver_[j], at_);
            }
            return false;
        }
        waving_ = true;
        return true;
    }

    // Skips to the last period boundary at or before `now` and ends the waves
    // there. Returns true (for sync's `ended`).
    bool end_waves(Cycle now) {
        if (now > at_) skip_whole_periods(now);
        waving_ = false;
        quiescent_ = false;
        next_valid_ = false;
        CycleAt stamp(avr_, at_);
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (has_comp_[i] && com_[i] != 0) pins_->end_wave(driver_[i], at_);
        }
        return true;
    }

    // Set, and staying set: an enabled vector will soon clear it (and would
    // only wake the model again right away).
    bool flag_set(const avr_int_vector_t& v) const {
        return v.raised.reg != 0 && avr_regbit_get(avr_, v.raised) != 0 && avr_regbit_get(avr_, v.enable) == 0;
    }

    // While quiescent the state repeats every `period_` timer clocks from the anchor.
    void skip_whole_periods(Cycle now) {
        next_valid_ = false;
        const std::uint64_t anchor = tick_index(anchor_at_);
        const std::uint64_t whole = (tick_index(now) - anchor) / period_ * period_;
        if (anchor + whole <= tick_index(at_)) return;
        anchor_at_ = tick_cycle(anchor + whole);
        at_ = anchor_at_;
        value_ = anchor_value_;
        dir_ = anchor_dir_;
    }

    // --- configuration ------------------------------------------------------------

    std::vector<avr_int_vector_t*> vectors() const {
        std::vector<avr_int_vector_t*> v;
        if (t_->overflow.vector != 0) v.push_back(&t_->overflow);
        if (t_->icr.vector != 0) v.push_back(&t_->icr);
        for (auto& c : t_->comp) {
            if (c.r_ocr != 0 && c.interrupt.vector != 0) v.push_back(&c.interrupt);
        }
        return v;
    }

    // Mode, clock and compare outputs from the control registers.
    void configure() {
        unsigned wgm = 0;
        for (unsigned i = 0; i < shape_.wgm_bits; ++i) wgm |= static_cast<unsigned>(avr_regbit_get(avr_, shape_.wgm[i])) << i;
        const Mode m = shape_.modes[wgm];
        if (!m.pwm()) {
            // Normal and CTC: no double buffering, OCRnx is used as written.
            for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
                if (has_comp_[i]) ocr_[i] = ocr_register(i);
            }
        }
        mode_ = m;
        // Only the dual-slope modes count down (ATmega2560 §17.9.1-2: in
        // Normal and CTC mode "the counting direction is always up"; fast PWM
        // is single-slope too). A timer switched out of phase-correct PWM while
        // it counted down counts up from its current value.
        if (!m.dual_slope()) {
            dir_ = 1;
            anchor_dir_ = 1;
        }
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            com_[i] = has_comp_[i] ? avr_regbit_get(avr_, t_->comp[i].com) : 0;
        }

        const int cs = avr_regbit_get_array(avr_, t_->cs, 3) & 7;
        const int div = shape_.divisors[cs];
        ext_edge_ = 0;
        if (div <= 0) {
            clock_divisor_ = 0;
            if (div < 0 && ext_irq_ != nullptr) ext_edge_ = div == -2 ? 2 : 1;
        } else {
            clock_divisor_ = static_cast<std::uint32_t>(div);
            num_ = clock_divisor_;
            den_ = 1;
            shift_ = 0;
            while ((1u << shift_) < clock_divisor_) ++shift_;  // 1, 8, 32, ..., 1024
            if (t_->as2.reg != 0 && avr_regbit_get(avr_, t_->as2) != 0) {
                // AS2 = 1: clocked from the TOSC crystal (simavr's ext_clock, 32768 Hz by default).
                const auto crystal = static_cast<std::uint64_t>(t_->ext_clock > 0 ? t_->ext_clock + 0.5f : 32768.0f);
                num_ = static_cast<std::uint64_t>(clock_divisor_) * avr_->frequency;
                den_ = crystal;
            }
        }
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (has_comp_[i]) pins_->set(driver_[i], connected(i), oc_[i]);
        }
    }

    // FOCnx strobes (non-PWM modes only): the compare output action, no flag,
    // no clear of the timer (§15.5.1 / §16.7.1).
    void force(std::uint8_t strobes) {
        if (mode_.pwm()) return;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            if (!has_comp_[i] || (strobes & shape_.foc_bit[i]) == 0 || shape_.foc_bit[i] == 0) continue;
            bool level = oc_[i];
            compare_action(i, 1, level);
            if (level != oc_[i]) {
                oc_[i] = level;
                pins_->set(driver_[i], connected(i), level);
            }
        }
    }

    void reset_state() {
        forget_replay();
        waving_ = false;  // CompareOutputPins::after_reset ended the waves
        next_valid_ = false;
        avr_cycle_timer_cancel(avr_, &on_event, this);
        avr_cycle_timer_cancel(avr_, &on_noise_canceler, this);
        value_ = 0;
        dir_ = 1;
        at_ = avr_->cycle;
        block_compare_ = false;
        quiescent_ = false;
        period_start_ = false;
        mode_ = shape_.modes[0];
        clock_divisor_ = 0;
        ext_edge_ = 0;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
            ocr_[i] = 0;
            oc_[i] = false;
            com_[i] = 0;
        }
        prescaler_->base = avr_->cycle;
        prescaler_->held = false;
        if (icp_irq_ != nullptr) {
            avr_unconnect_irq(icp_irq_, t_->io.irq + TIMER_IRQ_IN_ICP);
            icp_level_ = (icp_irq_->value & 0xFF) != 0;
        }
    }

    // --- hooks --------------------------------------------------------------------

    static void on_control_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<TimerModel*>(hook.context());
        self->sync(avr->cycle);
        std::uint8_t strobes = 0;
        if (addr == self->shape_.foc_reg) {
            for (std::uint8_t bit : self->shape_.foc_bit) strobes = static_cast<std::uint8_t>(strobes | (value & bit));
            value = static_cast<std::uint8_t>(value & ~strobes);  // FOCnx always read as zero
        }
        avr_core_watch_write(avr, addr, value);
        self->configure();
        if (strobes != 0) self->force(strobes);
        self->reschedule();
    }

    static void on_tcnt_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<TimerModel*>(hook.context());
        self->sync(avr->cycle);
        avr_core_watch_write(avr, addr, value);
        // 16-bit: the high byte written before (TEMP) goes in with the low byte.
        const avr_io_addr_t h = self->t_->r_tcnth;
        self->value_ = static_cast<std::uint16_t>(value | (h != 0 ? avr->data[h] << 8 : 0));
        // §16.7.2: "All CPU write operations to the TCNT1 Register will block
        // any compare match that occurs in the next timer clock cycle, even
        // when the timer is stopped" (§15.5.2 for TCNT0).
        self->block_compare_ = true;
        self->reschedule();
    }

    static std::uint8_t on_tcnt_read(IoReadHook& hook, avr_t* avr, avr_io_addr_t) {
        auto* self = static_cast<TimerModel*>(hook.context());
        self->sync(avr->cycle);
        const std::uint16_t v = self->value_;
        // Reading the low byte latches the high byte (TEMP) for the next read.
        if (self->t_->r_tcnth != 0) avr->data[self->t_->r_tcnth] = static_cast<std::uint8_t>(v >> 8);
        return static_cast<std::uint8_t>(v & 0xFF);
    }

    static void on_ocr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<TimerModel*>(hook.context());
        self->sync(avr->cycle);
        avr_core_watch_write(avr, addr, value);
        if (!self->mode_.pwm()) {
            for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
                if (self->has_comp_[i] && self->t_->comp[i].r_ocr == addr) self->ocr_[i] = self->ocr_register(i);
            }
        }
        self->reschedule();
    }

    static void on_icr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<TimerModel*>(hook.context());
        self->sync(avr->cycle);
        avr_core_watch_write(avr, addr, value);  // ICRn as TOP is not double buffered (§16.9.3)
        self->reschedule();
    }

    // Input capture (§16.6): ICRn <- TCNTn on the edge ICESn selects, ICFn set;
    // with ICNCn the edge counts after four equal samples, four cycles later.
    static void on_icp_pin(avr_irq_t*, std::uint32_t value, void* param) {
        auto* self = static_cast<TimerModel*>(param);
        const bool level = (value & 0xFF) != 0;
        self->icnc_pending_level_ = level;
        if (avr_regbit_get(self->avr_, self->shape_.icnc) != 0) {
            // Restarts the four-sample window: a pulse shorter than that is filtered out.
            avr_cycle_timer_register(self->avr_, 4, &on_noise_canceler, self);
            return;
        }
        self->capture_edge(level, self->avr_->cycle);
    }

    static avr_cycle_count_t on_noise_canceler(avr_t*, avr_cycle_count_t when, void* param) {
        auto* self = static_cast<TimerModel*>(param);
        self->capture_edge(self->icnc_pending_level_, when);
        return 0;
    }

    void capture_edge(bool level, Cycle at) {
        if (level == icp_level_) return;
        icp_level_ = level;
        if (mode_.top == TopFrom::Icr) return;  // ICRn is TOP: the input capture is disabled
        const bool rising_selected = avr_regbit_get(avr_, t_->ices) != 0;
        if (level != rising_selected) return;
        CycleAt stamp(avr_, at);
        sync(at);
        avr_->data[t_->r_icr] = static_cast<std::uint8_t>(value_ & 0xFF);
        if (t_->r_icrh != 0) avr_->data[t_->r_icrh] = static_cast<std::uint8_t>(value_ >> 8);
        avr_raise_interrupt(avr_, &t_->icr);
    }

    // External clock on Tn (CSn2:0 = 110 falling, 111 rising): one timer clock
    // per edge, at the cycle of the edge (silicon: 2.5..3.5 cycles later, §17.3).
    static void on_ext_pin(avr_irq_t* irq, std::uint32_t value, void* param) {
        auto* self = static_cast<TimerModel*>(param);
        if (self->ext_edge_ == 0) return;
        const bool level = (value & 0xFF) != 0;
        const bool old = (irq->value & 0xFF) != 0;
        if (level == old || level != (self->ext_edge_ == 2)) return;
        avr_t* avr = self->avr_;
        if (self->at_ < avr->cycle) self->at_ = avr->cycle;
        self->next_valid_ = false;
        if (self->distance() == 1) {
            self->event(avr->cycle);
        } else {
            self->advance(1);
        }
    }

    // A flag was cleared (TIFRn write, or the vector was taken): a quiescent
    // timer must set it again at the next match.
    static void on_flag_change(avr_irq_t*, std::uint32_t value, void* param) {
        auto* self = static_cast<TimerModel*>(param);
        if (value != 0 || !self->quiescent_) return;
        self->sync(self->avr_->cycle);
        self->reschedule();
    }

    static void on_io_reset(avr_io_t* io) {
        TimerModel* self = FixState<TimerModel>::find(io);
        if (self == nullptr) return;
        if (self->original_reset_ != nullptr) self->original_reset_(io);
        self->pins_->after_reset();
        self->reset_state();
    }

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

// GTCCR (PSRSYNC, PSRASY, TSM; §17.4.1) or, on the ATmega8/16/32, SFIOR
// (PSR10, PSR2): prescaler resets.
class PrescalerResets {
public:
    PrescalerResets(avr_t* avr, Family family, std::vector<TimerModel*> timers, Prescaler& sync, Prescaler& async)
        : family_(family), timers_(std::move(timers)), sync_(&sync), async_(&async) {
        const avr_io_addr_t reg = family == Family::Modern ? 0x43 : 0x50;  // GTCCR / SFIOR
        hook_ = std::make_unique<IoWriteHook>(avr, reg, &on_write, this);
    }

private:
    static void on_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<PrescalerResets*>(hook.context());
        const Cycle now = avr->cycle;
        for (TimerModel* t : self->timers_) t->sync(now);
        const bool tsm = self->family_ == Family::Modern && (value & 0x80) != 0;
        const bool reset_sync = (value & 0x01) != 0;   // PSRSYNC / PSR10
        const bool reset_async = (value & 0x02) != 0;  // PSRASY / PSR2
        auto apply = [&](Prescaler& p, bool reset) {
            if (reset) {
                p.base = now;
                p.held = tsm;
            } else if (p.held && !tsm) {
                p.held = false;
                p.base = now;
            }
        };
        apply(*self->sync_, reset_sync);
        apply(*self->async_, reset_async);
        // The reset bits clear themselves unless TSM holds them.
        if (!tsm) value = static_cast<std::uint8_t>(value & ~0x03);
        hook.write_original(avr, addr, value);
        for (TimerModel* t : self->timers_) t->reschedule();
    }

    Family family_;
    std::vector<TimerModel*> timers_;
    Prescaler* sync_;
    Prescaler* async_;
    std::unique_ptr<IoWriteHook> hook_;
};

class TimerFix final : public Fix {
public:
    TimerFix(avr_t* avr, Family family) : pins_(*CompareOutputPins::of(avr)) {
        sync_.base = async_.base = avr->cycle;
        std::vector<TimerModel*> all;
        for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
            if (io->kind == nullptr || std::string_view(io->kind) != "timer") continue;
            auto* t = reinterpret_cast<avr_timer_t*>(io);
            if (t->r_tcnt == 0 || t->cs[0].reg == 0) continue;
            const Shape shape = shape_of(avr, t, family);
            timers_.push_back(std::make_unique<TimerModel>(avr, t, shape, shape.async_group ? async_ : sync_, pins_));
            all.push_back(timers_.back().get());
        }
        resets_ = std::make_unique<PrescalerResets>(avr, family, all, sync_, async_);
    }
    ~TimerFix() override {
        resets_.reset();
        timers_.clear();
    }

private:
    Prescaler sync_, async_;
    CompareOutputPins& pins_;  // install_port_overrides's
    std::vector<std::unique_ptr<TimerModel>> timers_;
    std::unique_ptr<PrescalerResets> resets_;
};

}  // namespace

void set_timer_replay(bool on) { TimerModel::set_replay_enabled(on); }

std::unique_ptr<Fix> install_timer_model(avr_t* avr) {
    Family family;
    if (avr->mmcu == nullptr || !family_of(avr->mmcu, family)) return nullptr;
    return std::make_unique<TimerFix>(avr, family);
}

}  // namespace avrbench
