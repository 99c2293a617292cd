// Timer/Counter model, its simavr side: the mode tables and register
// layout per part, the I/O hooks, prescaler resets and install_timer_model
// (what the model corrects: periph/timer/TimerModel.hpp).
#include "periph/timer/TimerModel.hpp"

#include <string_view>

namespace avrbench {
namespace timer_model {
namespace {

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


}  // namespace

TimerModel::TimerModel(avr_t* avr, avr_timer_t* timer, const Shape& shape, Prescaler& prescaler, CompareOutputPins& pins): avr_(avr), t_(timer), shape_(shape), prescaler_(&prescaler), pins_(&pins) {
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

TimerModel::~TimerModel() {
    FixState<TimerModel>::remove(&t_->io);
    t_->io.reset = original_reset_;
    avr_cycle_timer_cancel(avr_, &on_event, this);
    avr_cycle_timer_cancel(avr_, &on_noise_canceler, this);
    if (icp_irq_ != nullptr) avr_irq_unregister_notify(icp_irq_, &on_icp_pin, this);
    if (ext_irq_ != nullptr) avr_irq_unregister_notify(ext_irq_, &on_ext_pin, this);
    for (avr_int_vector_t* v : vectors()) avr_irq_unregister_notify(v->irq + AVR_INT_IRQ_PENDING, &on_flag_change, this);
}

std::vector<avr_int_vector_t*> TimerModel::vectors() const {
    std::vector<avr_int_vector_t*> v;
    if (t_->overflow.vector != 0) v.push_back(&t_->overflow);
    if (t_->icr.vector != 0) v.push_back(&t_->icr);
    for (auto& c : t_->comp) {
        if (c.r_ocr != 0 && c.interrupt.vector != 0) v.push_back(&c.interrupt);
    }
    return v;
}

void TimerModel::configure() {
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

void TimerModel::force(std::uint8_t strobes) {
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

void TimerModel::reset_state() {
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

void TimerModel::on_control_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
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

void TimerModel::on_tcnt_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
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

std::uint8_t TimerModel::on_tcnt_read(IoReadHook& hook, avr_t* avr, avr_io_addr_t) {
    auto* self = static_cast<TimerModel*>(hook.context());
    self->sync(avr->cycle);
    const std::uint16_t v = self->value_;
    // Reading the low byte latches the high byte (TEMP) for the next read.
    if (self->t_->r_tcnth != 0) avr->data[self->t_->r_tcnth] = static_cast<std::uint8_t>(v >> 8);
    return static_cast<std::uint8_t>(v & 0xFF);
}

void TimerModel::on_ocr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
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

void TimerModel::on_icr_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    auto* self = static_cast<TimerModel*>(hook.context());
    self->sync(avr->cycle);
    avr_core_watch_write(avr, addr, value);  // ICRn as TOP is not double buffered (§16.9.3)
    self->reschedule();
}

void TimerModel::on_icp_pin(avr_irq_t*, std::uint32_t value, void* param) {
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

avr_cycle_count_t TimerModel::on_noise_canceler(avr_t*, avr_cycle_count_t when, void* param) {
    auto* self = static_cast<TimerModel*>(param);
    self->capture_edge(self->icnc_pending_level_, when);
    return 0;
}

void TimerModel::capture_edge(bool level, Cycle at) {
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

void TimerModel::on_ext_pin(avr_irq_t* irq, std::uint32_t value, void* param) {
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

void TimerModel::on_flag_change(avr_irq_t*, std::uint32_t value, void* param) {
    auto* self = static_cast<TimerModel*>(param);
    if (value != 0 || !self->quiescent_) return;
    self->sync(self->avr_->cycle);
    self->reschedule();
}

void TimerModel::on_io_reset(avr_io_t* io) {
    TimerModel* self = FixState<TimerModel>::find(io);
    if (self == nullptr) return;
    if (self->original_reset_ != nullptr) self->original_reset_(io);
    self->pins_->after_reset();
    self->reset_state();
}

namespace {


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
}  // namespace timer_model

void set_timer_replay(bool on) { timer_model::TimerModel::set_replay_enabled(on); }

std::unique_ptr<Fix> install_timer_model(avr_t* avr) {
    timer_model::Family family;
    if (avr->mmcu == nullptr || !timer_model::family_of(avr->mmcu, family)) return nullptr;
    return std::make_unique<timer_model::TimerFix>(avr, family);
}

}  // namespace avrbench
