// Several MCUs on one board advanced in simulated-time order, exactly.
//
// The board tells the lockstep who can change what whom sees
// (add_influence: a net joining a pin or part of one MCU's clock to a pin or
// part of another's; the TWI bus is such a net). The MCU whose next step
// comes first runs - an awake one at its present, a dormant one (asleep, no
// interrupt on its way) at its next cycle timer - and may run up to the
// earliest time at which any MCU that influences it could act: an awake
// one's present, a dormant one's next cycle timer, or earlier when a change
// another MCU can make would wake it (Mcu::pin_change_may_interrupt: a pin
// with INTn/PCINTn enabled, a USART's RxD, the TWI bus...). It stops short
// of the present of any awake MCU it influences, so a change it makes never
// reaches an MCU that has already run past it. MCUs joined by nothing do not
// wait for each other at all: seed 001's four drive boards, which wake
// together for their current choppers, each run their burst alone while the
// interpolator sleeps with no interrupt a drive can raise.
//
// Everything outside an MCU that can change what it sees - a net delivering
// a level, the TWI bus - calls Mcu::before_external_change() first; the
// lockstep then brings that MCU, if it is dormant and behind, up to the
// running MCU's time (an exact jump: it has no event before then) and makes
// the running MCU yield after its instruction, so the bounds are worked out
// again. A dormant MCU is otherwise left where it is until its next event
// comes or the run ends.
//
// Parts joined by ports call each other directly, so each such group of parts
// has one clock (boards/Board.cpp); MCUs a group must share anyway (two MCUs
// sampling one part's analog outputs) are coupled() and never run ahead of
// each other. Clocks may differ (times compare as exact multiples of the
// least common multiple of the clocks' periods).
#pragma once

#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "mcu/Mcu.hpp"

namespace avrbench {

class Lockstep final : public PeerSync {
public:
    Lockstep() = default;
    ~Lockstep() override;
    Lockstep(const Lockstep&) = delete;
    Lockstep& operator=(const Lockstep&) = delete;

    void add(Mcu& mcu);
    const std::vector<Mcu*>& mcus() const { return mcus_; }
    // `a` and `b` never run ahead of each other's present time.
    void couple(const Mcu& a, const Mcu& b);
    // `from` can change what `to` sees, through `to`'s pin `through` (which
    // wakes `to` only as Mcu::pin_change_may_interrupt says), or through a
    // part on `to`'s clock or anything else (`through` nullptr: any change
    // may wake it). A board that declares none has every MCU influence every
    // other through anything (no MCU passes an awake one).
    void add_influence(const Mcu& from, const Mcu& to, const Pin* through);
    // Off: every MCU's horizon is its present time (strict lockstep), for
    // tests that compare the two.
    void set_lookahead(bool on) { lookahead_ = on; }
    // Tests: every turn, each MCU's kept turn entry is compared with one
    // worked out anew (std::logic_error when one changed unseen).
    void set_check_turns(bool on) { check_turns_ = on; }

    // Runs every MCU to `end_ps` picoseconds of simulated time (each stops at
    // the first instruction boundary at or after it). Halted MCUs drop out.
    // Returns Requested as soon as any callback asked one MCU to stop.
    StopReason run_until_ps(std::uint64_t end_ps);
    // From a callback inside a run (a pin or a line someone waits for): the
    // present run_until_ps returns Requested after the running MCU's
    // instruction. Outside a run it does nothing.
    void request_stop() {
        if (running_ == nullptr) return;
        requested_stop_ = true;
        running_->request_stop();
    }

    // Whole-board simulated time in picoseconds: the time of the MCU furthest behind.
    std::uint64_t now_ps() const;

    // PeerSync: `mcu` is about to see a change made by the running MCU.
    void reach(Mcu& mcu) override;

    // Catch-up jumps made (dormant MCUs brought forward to a running one).
    std::uint64_t catch_ups() const { return catch_ups_; }

private:
    // Times count units of 1 / lcm(the clocks) seconds: an MCU's cycle is
    // units_per_cycle_ of them. With every MCU on one clock a unit is a
    // cycle and 64 bits hold every time (run_turns<std::uint64_t>); with
    // mixed clocks the products need 128 bits.
    __extension__ using WideTime = unsigned __int128;
    template <typename Time>
    struct Turn {  // one MCU, looked at again after it ran (or reach() saw a change)
        Time present, next, action, at, earliest_action;
        bool awake, halted, may_run;
    };
    template <typename Time>
    static constexpr Time kNever = ~Time{0};
    template <typename Time>
    StopReason run_turns(std::uint64_t end_ps, std::vector<Turn<Time>>& turns);
    template <typename Time>
    void look_at(std::size_t k, Turn<Time>& t) const;
    template <typename Time>
    void check_turns(const std::vector<Turn<Time>>& turns) const;
    void mark_stale(std::size_t k);  // MCU k's turn entry is looked at again (every one when more than 64)
    void mark_stale(const Mcu& mcu);
    struct Influence {
        std::size_t from = 0;
        bool any_change_may_wake = false;
        std::vector<const Pin*> pins;  // pins of the influenced MCU that wake it only when enabled
        // may_wake() as last worked out (-1: not since the influenced MCU
        // last ran or reach() saw a change to it; it depends on its registers only).
        std::int8_t wakes = -1;
    };
    std::size_t index_of(const Mcu& mcu) const;
    bool coupled(const Mcu& a, const Mcu& b) const;
    bool may_wake(const Influence& influence, const Mcu& influenced) const;
    bool wakes(Influence& influence, const Mcu& influenced) const;  // may_wake, remembered
    template <typename Time>
    Time time_of(std::size_t k, Cycle cycle) const {
        if constexpr (sizeof(Time) == sizeof(Cycle)) return cycle;  // one clock: units are cycles, never is never
        return cycle == ~Cycle{0} ? kNever<Time> : static_cast<Time>(cycle) * units_per_cycle_[k];
    }
    template <typename Time>
    Cycle cycle_of(std::size_t k, Time t) const;  // the first cycle of MCU k at or after t
    void influence_everything();

    std::vector<Mcu*> mcus_;
    std::vector<std::uint64_t> units_per_cycle_;
    std::vector<std::vector<Influence>> influenced_by_;  // per MCU: who can change what it sees
    std::vector<std::vector<std::size_t>> influences_;   // per MCU: whose view it can change
    bool influences_declared_ = false;
    std::vector<Cycle> end_cycles_;  // run_until_ps's end, per MCU
    std::vector<Turn<std::uint64_t>> turns_one_clock_;
    std::vector<Turn<WideTime>> turns_mixed_clocks_;
    std::set<std::pair<const Mcu*, const Mcu*>> coupled_;
    bool lookahead_ = true;
    bool check_turns_ = false;
    std::uint64_t stale_ = ~std::uint64_t{0};  // bit k: MCU k's turn entry must be looked at again
    Mcu* running_ = nullptr;
    bool requested_stop_ = false;  // a catch-up run was stopped by a callback
    std::uint64_t catch_ups_ = 0;
};

// Cycle of `mcu` at or after `time_ps` picoseconds.
Cycle cycle_at_ps(const Mcu& mcu, std::uint64_t time_ps);
// Picoseconds at `cycle` of `mcu`, rounded down.
std::uint64_t ps_at_cycle(const Mcu& mcu, Cycle cycle);

}  // namespace avrbench
