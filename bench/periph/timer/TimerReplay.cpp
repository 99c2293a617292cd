// Timer/Counter model: a steady period recorded once and replayed, and
// periodic waves handed to the compare outputs (periph/timer/PeriodicOutput.hpp)
// while the timer is quiescent (periph/timer/TimerModel.hpp).
#include "periph/timer/TimerModel.hpp"

namespace avrbench::timer_model {

void TimerModel::forget_replay() {
    replay_.valid = false;
    replay_.tried = false;
    steady_periods_ = 0;
}

void TimerModel::maybe_record() {
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

bool TimerModel::any_enabled(std::uint8_t raises) const {
    for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i) {
        if (((raises >> i) & 1) && avr_regbit_get(avr_, t_->comp[i].interrupt.enable) != 0) return true;
    }
    if ((raises & kRaiseOverflow) != 0 && avr_regbit_get(avr_, t_->overflow.enable) != 0) return true;
    return (raises & kRaiseCapture) != 0 && avr_regbit_get(avr_, t_->icr.enable) != 0;
}

bool TimerModel::replay_event(Cycle when, Cycle& next_out) {
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

std::atomic<bool>& TimerModel::replay_enabled() {
    static std::atomic<bool> on{true};
    return on;
}

std::uint64_t TimerModel::period_clocks(bool& tov, bool& icf) const {
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

void TimerModel::maybe_quiesce() {
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

bool TimerModel::run_period_dry(Cycle period_cycles, DryRun& run) {
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

bool TimerModel::begin_waves(std::uint64_t period_clocks) {
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

bool TimerModel::end_waves(Cycle now) {
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

bool TimerModel::flag_set(const avr_int_vector_t& v) const {
    return v.raised.reg != 0 && avr_regbit_get(avr_, v.raised) != 0 && avr_regbit_get(avr_, v.enable) == 0;
}

void TimerModel::skip_whole_periods(Cycle now) {
    next_valid_ = false;
    const std::uint64_t anchor = tick_index(anchor_at_);
    const std::uint64_t whole = (tick_index(now) - anchor) / period_ * period_;
    if (anchor + whole <= tick_index(at_)) return;
    anchor_at_ = tick_cycle(anchor + whole);
    at_ = anchor_at_;
    value_ = anchor_value_;
    dir_ = anchor_dir_;
}

}  // namespace avrbench::timer_model
