#include "mcu/Lockstep.hpp"

#include <algorithm>
#include <bit>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <simavr/sim_avr.h>
#include <simavr/sim_interrupts.h>

namespace avrbench {
namespace {

__extension__ using u128 = unsigned __int128;  // exact products of 64-bit cycles and 32-bit clocks

// Mcu::dormant() and Mcu::next_event_cycle(), read in place: every turn
// looks at every MCU, and the calls into Mcu.cpp and simavr were a tenth of
// a turn's cost.
// (avr_has_pending_interrupts is "the pending FIFO is not empty", sim_interrupts.c.)
bool dormant_now(const avr_t* avr) {
    return avr->state == cpu_Sleeping && avr->interrupts.pending.read == avr->interrupts.pending.write;
}
Cycle next_event_now(const avr_t* avr) {
    const avr_cycle_timer_slot_p head = avr->cycle_timers.timer;
    return head == nullptr ? ~Cycle{0} : head->when;
}

// The first cycle of `mcu` at or after `other_cycle` of `other`.
Cycle cycle_at_time_of(const Mcu& mcu, const Mcu& other, Cycle other_cycle) {
    if (other_cycle == ~Cycle{0} || mcu.frequency_hz() == other.frequency_hz()) return other_cycle;
    const u128 num = static_cast<u128>(other_cycle) * mcu.frequency_hz();
    const u128 den = other.frequency_hz();
    const u128 c = (num + den - 1) / den;
    return c > ~Cycle{0} ? ~Cycle{0} : static_cast<Cycle>(c);
}

}  // namespace

Cycle cycle_at_ps(const Mcu& mcu, std::uint64_t time_ps) {
    const u128 num = static_cast<u128>(time_ps) * mcu.frequency_hz();
    return static_cast<Cycle>((num + kPsPerSecond - 1) / kPsPerSecond);
}

std::uint64_t ps_at_cycle(const Mcu& mcu, Cycle cycle) {
    return static_cast<std::uint64_t>(static_cast<u128>(cycle) * kPsPerSecond / mcu.frequency_hz());
}

Lockstep::~Lockstep() {
    for (Mcu* m : mcus_) m->set_peer_sync(nullptr);
}

void Lockstep::add(Mcu& mcu) {
    mcus_.push_back(&mcu);
    influenced_by_.emplace_back();
    influences_.emplace_back();
    // Times are counted in units of 1 / lcm(clocks) seconds, so each MCU's
    // cycle is a whole number of them.
    std::uint64_t lcm = 1;
    for (const Mcu* m : mcus_) lcm = std::lcm(lcm, static_cast<std::uint64_t>(m->frequency_hz()));
    units_per_cycle_.clear();
    for (const Mcu* m : mcus_) units_per_cycle_.push_back(lcm / m->frequency_hz());
    // One MCU needs no synchronising; with two, every MCU reports to us.
    if (mcus_.size() >= 2) {
        for (Mcu* m : mcus_) m->set_peer_sync(this);
    }
    if (!influences_declared_) influence_everything();
}

std::size_t Lockstep::index_of(const Mcu& mcu) const {
    for (std::size_t k = 0; k < mcus_.size(); ++k) {
        if (mcus_[k] == &mcu) return k;
    }
    throw std::logic_error("lockstep: MCU '" + mcu.name() + "' was not added");
}

void Lockstep::influence_everything() {
    for (std::size_t to = 0; to < mcus_.size(); ++to) {
        influenced_by_[to].clear();
        influences_[to].clear();
        for (std::size_t from = 0; from < mcus_.size(); ++from) {
            if (from == to) continue;
            Influence i;
            i.from = from;
            i.any_change_may_wake = true;
            influenced_by_[to].push_back(i);
            influences_[to].push_back(from);  // symmetric
        }
    }
}

void Lockstep::add_influence(const Mcu& from, const Mcu& to, const Pin* through) {
    if (&from == &to) return;
    if (!influences_declared_) {
        influences_declared_ = true;
        for (auto& v : influenced_by_) v.clear();
        for (auto& v : influences_) v.clear();
    }
    const std::size_t f = index_of(from), t = index_of(to);
    Influence* edge = nullptr;
    for (Influence& i : influenced_by_[t]) {
        if (i.from == f) edge = &i;
    }
    if (edge == nullptr) {
        influenced_by_[t].push_back(Influence{f, false, {}});
        edge = &influenced_by_[t].back();
        influences_[f].push_back(t);
    }
    if (through == nullptr || to.pin_feeds_a_peripheral(*through)) {
        edge->any_change_may_wake = true;
        edge->pins.clear();
    } else if (!edge->any_change_may_wake &&
               std::find(edge->pins.begin(), edge->pins.end(), through) == edge->pins.end()) {
        edge->pins.push_back(through);
    }
}

bool Lockstep::wakes(Influence& influence, const Mcu& influenced) const {
    if (influence.any_change_may_wake) return true;
    if (influence.wakes == -1) influence.wakes = may_wake(influence, influenced) ? 1 : 0;
    return influence.wakes == 1;
}

bool Lockstep::may_wake(const Influence& influence, const Mcu& influenced) const {
    if (influence.any_change_may_wake) return true;
    for (const Pin* p : influence.pins) {
        if (influenced.pin_interrupt_enabled(*p)) return true;
    }
    return false;
}

template <typename Time>
Cycle Lockstep::cycle_of(std::size_t k, Time t) const {
    if constexpr (sizeof(Time) == sizeof(Cycle)) {
        return t;  // one clock
    } else {
        if (t == kNever<Time>) return ~Cycle{0};
        if (units_per_cycle_[k] == 1) return t > ~Cycle{0} ? ~Cycle{0} : static_cast<Cycle>(t);  // equal clocks: no division
        const Time c = (t + units_per_cycle_[k] - 1) / units_per_cycle_[k];
        return c > ~Cycle{0} ? ~Cycle{0} : static_cast<Cycle>(c);
    }
}

void Lockstep::couple(const Mcu& a, const Mcu& b) {
    if (&a == &b) return;
    coupled_.insert({&a, &b});
    coupled_.insert({&b, &a});
}

bool Lockstep::coupled(const Mcu& a, const Mcu& b) const { return !coupled_.empty() && coupled_.count({&a, &b}) != 0; }

std::uint64_t Lockstep::now_ps() const {
    // The running MCU furthest behind; once all have halted, the last to halt.
    std::uint64_t now = std::numeric_limits<std::uint64_t>::max(), halted_at = 0;
    for (const Mcu* m : mcus_) {
        const std::uint64_t t = ps_at_cycle(*m, m->cycle());
        if (m->halted()) halted_at = std::max(halted_at, t);
        else now = std::min(now, t);
    }
    return now == std::numeric_limits<std::uint64_t>::max() ? halted_at : now;
}

void Lockstep::reach(Mcu& mcu) {
    Mcu* const runner = running_;
    if (runner == nullptr || &mcu == runner) return;
    // Whatever changes next may change its state: its turn entry is looked at again.
    mark_stale(mcu);
    // Whatever changes now may wake `mcu` or change its outputs: every
    // bound is worked out again after the runner's instruction.
    runner->request_yield();
    if (mcu.halted() || mcu.in_run() || !mcu.dormant()) return;
    const Cycle target = cycle_at_time_of(mcu, *runner, runner->cycle());
    if (mcu.cycle() >= target) return;
    ++catch_ups_;
    running_ = &mcu;
    if (mcu.run_until(target) == StopReason::Requested) requested_stop_ = true;
    running_ = runner;
}

StopReason Lockstep::run_until_ps(std::uint64_t end_ps) {
    const bool one_clock = std::all_of(units_per_cycle_.begin(), units_per_cycle_.end(), [](std::uint64_t u) { return u == 1; });
    return one_clock ? run_turns(end_ps, turns_one_clock_) : run_turns(end_ps, turns_mixed_clocks_);
}

template <typename Time>
void Lockstep::look_at(std::size_t k, Turn<Time>& t) const {
    const Mcu& m = *mcus_[k];
    const avr_t* const avr = m.avr();
    t.halted = m.halted();
    t.present = time_of<Time>(k, avr->cycle);
    t.awake = !t.halted && !(lookahead_ && dormant_now(avr));
    t.next = t.awake || t.halted ? kNever<Time> : time_of<Time>(k, next_event_now(avr));
    // The earliest time it could act: its present when awake; asleep, its next cycle timer.
    t.action = t.halted ? kNever<Time> : t.awake ? t.present : t.next;
    t.may_run = !t.halted && avr->cycle < end_cycles_[k];
    t.at = t.awake ? t.present : std::min(t.next, time_of<Time>(k, end_cycles_[k]));
}

template <typename Time>
void Lockstep::check_turns(const std::vector<Turn<Time>>& turns) const {
    for (std::size_t k = 0; k < mcus_.size(); ++k) {
        Turn<Time> fresh{};
        look_at(k, fresh);
        const Turn<Time>& kept = turns[k];
        if (fresh.present != kept.present || fresh.next != kept.next || fresh.action != kept.action || fresh.at != kept.at ||
            fresh.awake != kept.awake || fresh.halted != kept.halted || fresh.may_run != kept.may_run) {
            throw std::logic_error("lockstep: the turn entry kept for MCU '" + mcus_[k]->name() +
                                   "' is out of date (it changed without running or reach())");
        }
        for (const Influence& i : influenced_by_[k]) {
            if (i.wakes != -1 && (i.wakes == 1) != may_wake(i, *mcus_[k])) {
                throw std::logic_error("lockstep: what may wake MCU '" + mcus_[k]->name() +
                                       "' changed without it running or reach()");
            }
        }
    }
}

void Lockstep::mark_stale(std::size_t k) {
    if (k < 64) stale_ |= std::uint64_t{1} << k;
}

void Lockstep::mark_stale(const Mcu& mcu) {
    for (std::size_t k = 0; k < mcus_.size(); ++k) {
        if (mcus_[k] == &mcu) mark_stale(k);
    }
}

template <typename Time>
StopReason Lockstep::run_turns(std::uint64_t end_ps, std::vector<Turn<Time>>& turns) {
    constexpr Time kNeverTime = kNever<Time>;
    const std::size_t n = mcus_.size();
    requested_stop_ = false;
    bool stopped = false;
    end_cycles_.resize(n);
    turns.resize(n);
    // Every turn reads these for every MCU: local pointers, which the
    // stores into `turn` below cannot make the compiler load again.
    Turn<Time>* const turn = turns.data();
    Mcu* const* const mcus = mcus_.data();
    Cycle* const end_cycles = end_cycles_.data();
    for (std::size_t k = 0; k < n; ++k) end_cycles[k] = cycle_at_ps(*mcus[k], end_ps);
    stale_ = ~std::uint64_t{0};
    for (;;) {
        // What each MCU's turn entry says changes only when that MCU runs
        // (the runner, or one reach() brought forward) or something outside
        // it changes what it sees (reach() again): only those are looked at
        // again. More than 64 MCUs: every one, every turn.
        const auto refresh = [&](std::size_t k) {
            look_at(k, turn[k]);
            for (Influence& i : influenced_by_[k]) i.wakes = -1;
        };
        if (n > 64) {
            for (std::size_t k = 0; k < n; ++k) refresh(k);
        } else {
            for (std::uint64_t left = n == 64 ? stale_ : stale_ & ((std::uint64_t{1} << n) - 1); left != 0; left &= left - 1) {
                refresh(static_cast<std::size_t>(std::countr_zero(left)));
            }
        }
        stale_ = 0;
        if (__builtin_expect(check_turns_, 0)) check_turns(turns);
        // The MCU whose next step comes first (an awake one's present, a
        // dormant one's next event or the run's end), and the two earliest
        // actions of all MCUs with the first's index: the earliest of every
        // MCU but the runner, whichever it is.
        std::size_t runner = n;
        Time runner_at = kNeverTime;
        Time first_action = kNeverTime, second_action = kNeverTime;
        std::size_t first_actor = n;
        for (std::size_t k = 0; k < n; ++k) {
            const Turn<Time>& t = turn[k];
            if (t.action < first_action) {
                second_action = first_action;
                first_action = t.action;
                first_actor = k;
            } else if (t.action < second_action) {
                second_action = t.action;
            }
            if (!t.may_run) continue;
            if (runner == n || t.at < runner_at) {
                runner = k;
                runner_at = t.at;
            }
        }
        if (runner == n) break;
        // The earliest time each other MCU could act: its present when awake;
        // asleep, its next cycle timer, or the earliest action of an MCU other
        // than the runner that could wake it sooner. (When the runner wakes
        // one, reach() makes it yield at once and the bounds are worked out
        // again, so its own wake-ups never need to hold it back.)
        Mcu& behind = *mcus[runner];
        // Before any wake-up is counted, the earliest action of an MCU
        // other than the runner is its own.
        const auto runner_bound = [&](Time Turn<Time>::*earliest) {
            Time b = kNeverTime;
            for (const Influence& i : influenced_by_[runner]) b = std::min(b, turn[i.from].*earliest);
            for (const std::size_t x : influences_[runner]) {
                if (turn[x].awake) b = std::min(b, turn[x].present);
            }
            return b;
        };
        Time bound = runner_bound(&Turn<Time>::action);
        // The wake-ups below only lower an MCU's earliest action to another's
        // (never below the earliest of them all, the runner aside): a bound
        // already there is the answer, and that is most turns of two awake
        // MCUs taking turns.
        const Time earliest_but_runner = first_actor == runner ? second_action : first_action;
        if (lookahead_ && bound > earliest_but_runner) {
            for (std::size_t k = 0; k < n; ++k) turn[k].earliest_action = k == runner ? kNeverTime : turn[k].action;
            for (bool changed = true; changed;) {
                changed = false;
                for (std::size_t k = 0; k < n; ++k) {
                    Turn<Time>& t = turn[k];
                    if (k == runner || t.awake || t.halted) continue;
                    for (Influence& i : influenced_by_[k]) {
                        if (turn[i.from].earliest_action < t.earliest_action && wakes(i, *mcus[k])) {
                            t.earliest_action = turn[i.from].earliest_action;
                            changed = true;
                        }
                    }
                }
            }
            bound = runner_bound(&Turn<Time>::earliest_action);
        }
        if (!coupled_.empty()) {
            for (std::size_t k = 0; k < n; ++k) {
                if (k != runner && !mcus[k]->halted() && coupled(behind, *mcus[k])) bound = std::min(bound, turn[k].present);
            }
        }
        // At least one instruction, or two cores at the same time would never move.
        const Cycle target = std::max(std::min(end_cycles[runner], cycle_of<Time>(runner, bound)), behind.cycle() + 1);
        running_ = &behind;
        const StopReason r = behind.run_until(target);
        running_ = nullptr;
        mark_stale(runner);
        if ((r == StopReason::Requested || requested_stop_) && !stopped) {
            // The run ends at the requesting instruction's time: every MCU
            // still behind it (awake ones that did not need to wait, dormant
            // ones left where they slept) is brought to it first, so whatever
            // the caller does next happens at one time on the whole board.
            stopped = true;
            const Time stop_at = time_of<Time>(runner, behind.cycle());
            for (std::size_t k = 0; k < n; ++k) end_cycles[k] = std::min(end_cycles[k], cycle_of<Time>(k, stop_at));
            stale_ = ~std::uint64_t{0};
        }
        requested_stop_ = false;
    }
    if (stopped) return StopReason::Requested;
    for (const Mcu* m : mcus_) {
        if (!m->halted()) return StopReason::ReachedTarget;
    }
    return StopReason::Halted;
}

}  // namespace avrbench
