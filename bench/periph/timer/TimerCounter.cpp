// Timer/Counter model: time and timer clocks, counting, compare matches and
// flags, scheduling the next event (periph/timer/TimerModel.hpp).
#include "periph/timer/TimerModel.hpp"

namespace avrbench::timer_model {

void TimerModel::sync(Cycle now) {
    const bool ended = waving_ && end_waves(now);
    sync_counter(now);
    if (ended) arm();
}

void TimerModel::sync_counter(Cycle now) {
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

void TimerModel::reschedule() {
    quiescent_ = false;
    next_valid_ = false;
    forget_replay();
    arm();
}

std::uint64_t TimerModel::tick_index(Cycle c) const {
    const Cycle base = prescaler_->base;
    if (c < base) return 0;
    if (den_ == 1) return (c - base) >> shift_;  // clk_I/O / N, N a power of two
    const Wide x = static_cast<Wide>(c - base + 1) * den_ - 1;
    return static_cast<std::uint64_t>(x / num_);
}

Cycle TimerModel::tick_cycle(std::uint64_t k) const {
    if (den_ == 1) return prescaler_->base + (k << shift_);
    return prescaler_->base + static_cast<Cycle>(static_cast<Wide>(k) * num_ / den_);
}

std::uint16_t TimerModel::ocr_register(int i) const {
    const auto& c = t_->comp[i];
    return static_cast<std::uint16_t>(avr_->data[c.r_ocr] | (c.r_ocrh != 0 ? avr_->data[c.r_ocrh] << 8 : 0));
}

std::uint16_t TimerModel::icr_register() const {
    return static_cast<std::uint16_t>(avr_->data[t_->r_icr] | (t_->r_icrh != 0 ? avr_->data[t_->r_icrh] << 8 : 0));
}

std::uint16_t TimerModel::top() const {
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

std::uint64_t TimerModel::distance() const {
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

bool TimerModel::top_blocked(std::uint16_t v, std::uint16_t top_value) const {
    return block_compare_ && mode_.top != TopFrom::Fixed && v == top_value;
}

void TimerModel::advance(std::uint64_t n) {
    if (n == 0) return;
    value_ = static_cast<std::uint16_t>(dir_ > 0 ? value_ + n : value_ - n);
    block_compare_ = false;
}

void TimerModel::event(Cycle t) {
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

void TimerModel::apply(Cycle t, const Outcome& out) {
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

void TimerModel::compare_action(int i, int match_dir, bool& level) const {
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

bool TimerModel::connected(int i) const {
    const std::uint8_t com = com_[i];
    if (com == 0) return false;
    if (com == 1 && mode_.pwm() && !(i == 0 && mode_.com1_toggles_a)) return false;  // "reserved"/disconnected
    return true;
}

void TimerModel::arm() {
    if (in_event_) {
        rearmed_ = true;  // on_event returns the next cycle itself
        return;
    }
    avr_cycle_timer_cancel(avr_, &on_event, this);
    const Cycle next = next_event_cycle();
    if (next == 0) return;
    avr_cycle_timer_register(avr_, next > avr_->cycle ? next - avr_->cycle : 0, &on_event, this);
}

Cycle TimerModel::next_event_cycle() const {
    if (!ticking() || quiescent_) return 0;
    if (next_valid_) return next_cache_;
    return tick_cycle(tick_index(at_) + distance());
}

avr_cycle_count_t TimerModel::on_event(avr_t*, avr_cycle_count_t when, void* param) {
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

}  // namespace avrbench::timer_model
