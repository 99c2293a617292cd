#include "mcu/TimingProfile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

extern "C" {
#include <sim_interrupts.h>
#include <sim_irq.h>
}

#include "mcu/Mcu.hpp"
#include "core/VectorNames.hpp"

namespace avrbench {

void CycleStats::add(Cycle value) {
    ++histogram_[value];
    ++count_;
}

Cycle CycleStats::quantile(double fraction) const {
    if (count_ == 0) return 0;
    const auto needed = static_cast<std::uint64_t>(std::ceil(fraction * static_cast<double>(count_)));
    std::uint64_t seen = 0;
    for (const auto& [value, n] : histogram_) {
        seen += n;
        if (seen >= std::max<std::uint64_t>(needed, 1)) return value;
    }
    return histogram_.rbegin()->first;
}

TimingProfiler::TimingProfiler(Mcu& mcu) : mcu_(mcu), avr_(mcu.avr()) {
    hooks_.reserve(static_cast<std::size_t>(avr_->interrupts.vector_count));
    for (int i = 0; i < avr_->interrupts.vector_count; ++i) {
        avr_int_vector_t* v = avr_->interrupts.vector[i];
        hooks_.push_back({this, v});
        avr_irq_register_notify(v->irq + AVR_INT_IRQ_PENDING, &on_pending, &hooks_.back());
        avr_irq_register_notify(v->irq + AVR_INT_IRQ_RUNNING, &on_running, &hooks_.back());
    }
    interrupts_on_ = avr_->sreg[S_I] != 0;
    off_since_ = avr_->cycle;
}

TimingProfiler::~TimingProfiler() {
    for (std::size_t i = 0; i < hooks_.size(); ++i) {
        avr_int_vector_t* v = avr_->interrupts.vector[i];
        avr_irq_unregister_notify(v->irq + AVR_INT_IRQ_PENDING, &on_pending, &hooks_[i]);
        avr_irq_unregister_notify(v->irq + AVR_INT_IRQ_RUNNING, &on_running, &hooks_[i]);
    }
}

void TimingProfiler::on_pending(avr_irq_t*, std::uint32_t value, void* param) {
    auto* hook = static_cast<Hook*>(param);
    TimingProfiler& self = *hook->self;
    const int vector = hook->vector->vector;
    if (value == 0) {
        self.pending_since_.erase(vector);  // cleared by software, or served (after RUNNING)
        return;
    }
    // simavr raises the flag's IRQ whether or not the interrupt is enabled,
    // and again when it is enabled with the flag set: latency counts from
    // the raise that found it enabled.
    if (avr_regbit_get(self.avr_, hook->vector->enable) == 0) return;
    self.pending_since_[vector] = self.avr_->cycle;
}

void TimingProfiler::on_running(avr_irq_t*, std::uint32_t value, void* param) {
    auto* hook = static_cast<Hook*>(param);
    TimingProfiler& self = *hook->self;
    if (value == 0) {
        ++self.reti_pending_;  // finished at the end of the RETI, in after_step
        return;
    }
    // The entry's cycle is taken at the end of this step: simavr serves an
    // interrupt at the end of a step, and periph/interrupts/InterruptTiming adds
    // the response cycles in its own hook on this IRQ, which may run after
    // this one.
    const int vector = hook->vector->vector;
    VectorProfile& profile = self.vectors_[vector];
    profile.vector = vector;
    Cycle raised = ~Cycle{0};
    if (const auto it = self.pending_since_.find(vector); it != self.pending_since_.end()) {
        raised = it->second;
        self.pending_since_.erase(it);
    }
    self.stack_.push_back({vector, ~Cycle{0}, raised, 0});
    profile.max_depth = std::max(profile.max_depth, static_cast<int>(self.stack_.size()));
    self.entered_vector_ = vector;
}

void TimingProfiler::reset() {
    stack_.clear();
    pending_since_.clear();
    reti_pending_ = 0;
    entered_vector_ = -1;
    interrupts_on_ = false;
    off_since_ = avr_->cycle;
    off_pc_ = 0;
    off_vector_ = -2;
}

void TimingProfiler::after_step(Cycle cycle_before, bool was_sleeping, std::uint32_t pc_before) {
    const Cycle now = avr_->cycle;
    const Cycle delta = now - std::min(now, cycle_before);
    (was_sleeping ? sleeping_ : active_) += delta;
    if (entered_vector_ >= 0) {
        for (Active& a : stack_) {
            if (a.entry != ~Cycle{0}) continue;
            a.entry = now;
            if (a.raised != ~Cycle{0}) vectors_[a.vector].latency_cycles.add(now - std::min(now, a.raised));
        }
    }

    for (; reti_pending_ > 0; --reti_pending_) {
        if (stack_.empty()) break;
        const Active done = stack_.back();
        stack_.pop_back();
        const Cycle inclusive = now - std::min(now, done.entry);
        VectorProfile& profile = vectors_[done.vector];
        ++profile.runs;
        profile.inclusive_cycles.add(inclusive);
        profile.exclusive_cycles.add(inclusive - std::min(inclusive, done.nested));
        if (!stack_.empty()) stack_.back().nested += inclusive;
    }
    reti_pending_ = 0;

    const auto sp = static_cast<std::uint16_t>(avr_->data[R_SPL] | (avr_->data[R_SPH] << 8));
    if (sp < lowest_sp_ && !mcu_.sp_half_written_by(pc_before)) {
        lowest_sp_ = sp;
        lowest_sp_pc_ = entered_vector_ >= 0 ? avr_->pc : pc_before;
        lowest_sp_cycle_ = now;
    }

    const bool on = avr_->sreg[S_I] != 0;
    if (on != interrupts_on_) {
        if (!on) {
            // Cleared: by a vector's entry (from its first instruction) or by CLI / an SREG write.
            off_vector_ = entered_vector_;
            off_since_ = entered_vector_ >= 0 && !stack_.empty() ? stack_.back().entry : now;
            off_pc_ = entered_vector_ >= 0 ? avr_->pc : pc_before;
        } else if (off_vector_ == -2) {
            first_sei_ = now;  // the reset's stretch ends: not an "interrupts off" of the firmware's making
        } else {
            const Cycle stretch = now - std::min(now, off_since_);
            if (stretch > longest_off_) {
                longest_off_ = stretch;
                longest_off_start_ = off_since_;
                longest_off_pc_ = off_pc_;
                longest_off_vector_ = off_vector_;
            }
        }
        interrupts_on_ = on;
    }
    entered_vector_ = -1;
}

namespace {

std::string us_text(Cycle cycles, std::uint32_t hz) {
    char text[48];
    std::snprintf(text, sizeof text, "%.3f us", static_cast<double>(cycles) * 1e6 / hz);
    return text;
}

std::string stats_text(const CycleStats& s) {
    char text[96];
    std::snprintf(text, sizeof text, "%llu/%llu/%llu/%llu", static_cast<unsigned long long>(s.min()),
                  static_cast<unsigned long long>(s.median()), static_cast<unsigned long long>(s.p99()),
                  static_cast<unsigned long long>(s.max()));
    return text;
}

std::string stats_json(const CycleStats& s) {
    char text[200];
    std::snprintf(text, sizeof text, "{\"count\": %llu, \"min\": %llu, \"median\": %llu, \"p99\": %llu, \"max\": %llu}",
                  static_cast<unsigned long long>(s.count()), static_cast<unsigned long long>(s.min()),
                  static_cast<unsigned long long>(s.median()), static_cast<unsigned long long>(s.p99()),
                  static_cast<unsigned long long>(s.max()));
    return text;
}

// A byte address as the summary prints it ("0x04d2"), beside the JSON's number.
std::string pc_hex(std::uint32_t pc_bytes) {
    char text[16];
    std::snprintf(text, sizeof text, "0x%04x", pc_bytes);
    return text;
}

std::string json_string(const std::string& text) {
    std::string out = "\"";
    for (const char c : text) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char esc[8];
            std::snprintf(esc, sizeof esc, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
            out += esc;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

}  // namespace

std::vector<std::string> TimingProfiler::summary_lines() const {
    std::vector<std::string> out;
    const std::uint32_t hz = mcu_.frequency_hz();
    const Cycle skipped = mcu_.idle_cycles_skipped();
    const double total = static_cast<double>(active_ + sleeping_ + skipped);
    char line[320];
    std::snprintf(line, sizeof line, "cpu %.2f%% executing, %.2f%% asleep, %.2f%% in the idle loop (skipped)",
                  total > 0 ? 100.0 * static_cast<double>(active_) / total : 0.0,
                  total > 0 ? 100.0 * static_cast<double>(sleeping_) / total : 0.0,
                  total > 0 ? 100.0 * static_cast<double>(skipped) / total : 0.0);
    out.push_back(line);
    const std::uint32_t floor = mcu_.elf().ram_end_of_static_data();
    if (lowest_sp_ != 0xFFFF) {
        std::snprintf(line, sizeof line, "stack lowest SP 0x%04x, %ld bytes above the end of .bss/.noinit, at %s (PC 0x%04x %s)",
                      lowest_sp_, static_cast<long>(lowest_sp_) + 1 - static_cast<long>(floor),
                      us_text(lowest_sp_cycle_, hz).c_str(), lowest_sp_pc_, mcu_.describe_pc(lowest_sp_pc_).c_str());
        out.push_back(line);
    }
    if (longest_off_ > 0) {
        std::string where;
        if (longest_off_vector_ >= 0) {
            where = "vector " + std::to_string(longest_off_vector_) + "'s entry";
        } else {
            char pc[16];
            std::snprintf(pc, sizeof pc, "%04x", longest_off_pc_);
            where = std::string("PC 0x") + pc + " " + mcu_.describe_pc(longest_off_pc_);
        }
        std::snprintf(line, sizeof line, "interrupts off at most %llu cycles (%s) from %s at %s",
                      static_cast<unsigned long long>(longest_off_), us_text(longest_off_, hz).c_str(), where.c_str(),
                      us_text(longest_off_start_, hz).c_str());
        out.push_back(line);
    }
    if (first_sei_ != ~Cycle{0}) {
        std::snprintf(line, sizeof line, "interrupts first enabled at %s", us_text(first_sei_, hz).c_str());
        out.push_back(line);
    }
    for (const auto& [vector, p] : vectors_) {
        const std::string name = vector_name(mcu_.mcu_type(), vector);
        std::snprintf(line, sizeof line,
                      "vector %d%s%s: %llu runs, cycles min/median/p99/max: inclusive %s, exclusive %s, latency %s; depth %d",
                      vector, name.empty() ? "" : " ", name.c_str(), static_cast<unsigned long long>(p.runs), stats_text(p.inclusive_cycles).c_str(),
                      stats_text(p.exclusive_cycles).c_str(), stats_text(p.latency_cycles).c_str(), p.max_depth);
        out.push_back(line);
    }
    return out;
}

std::string TimingProfiler::json() const {
    const std::uint32_t floor = mcu_.elf().ram_end_of_static_data();
    std::string out = "{\"mcu\": " + json_string(mcu_.name()) + ", \"clock_hz\": " + std::to_string(mcu_.frequency_hz()) +
                      ", \"cycles\": {\"executing\": " + std::to_string(active_) + ", \"asleep\": " +
                      std::to_string(sleeping_) + ", \"idle_loop_skipped\": " + std::to_string(mcu_.idle_cycles_skipped()) +
                      "}, \"stack\": {\"lowest_sp\": " + std::to_string(lowest_sp_) + ", \"headroom_bytes\": " +
                      std::to_string(static_cast<long>(lowest_sp_) + 1 - static_cast<long>(floor)) + ", \"pc\": " +
                      std::to_string(lowest_sp_pc_) + ", \"pc_hex\": " + json_string(pc_hex(lowest_sp_pc_)) + ", \"symbol\": " + json_string(mcu_.describe_pc(lowest_sp_pc_)) +
                      ", \"cycle\": " + std::to_string(lowest_sp_cycle_) + "}, \"interrupts_off\": {\"longest_cycles\": " +
                      std::to_string(longest_off_) + ", \"from_cycle\": " + std::to_string(longest_off_start_) +
                      ", \"vector\": " + std::to_string(longest_off_vector_) + ", \"pc\": " + std::to_string(longest_off_pc_) +
                      ", \"pc_hex\": " + json_string(pc_hex(longest_off_pc_)) +
                      ", \"first_sei_cycle\": " + (first_sei_ == ~Cycle{0} ? std::string("null") : std::to_string(first_sei_)) +
                      ", \"symbol\": " + json_string(mcu_.describe_pc(longest_off_pc_)) + "}, \"vectors\": [";
    bool first = true;
    for (const auto& [vector, p] : vectors_) {
        out += std::string(first ? "" : ", ") + "{\"vector\": " + std::to_string(vector) + ", \"name\": " +
               json_string(vector_name(mcu_.mcu_type(), vector)) + ", \"runs\": " +
               std::to_string(p.runs) + ", \"max_depth\": " + std::to_string(p.max_depth) +
               ", \"inclusive_cycles\": " + stats_json(p.inclusive_cycles) +
               ", \"exclusive_cycles\": " + stats_json(p.exclusive_cycles) +
               ", \"latency_cycles\": " + stats_json(p.latency_cycles) + "}";
        first = false;
    }
    return out + "]}";
}

}  // namespace avrbench
